// tessera-farm-load: how many workers can one coordinator feed? Starts tessera-server on loopback,
// submits a job of about --units work units of a tiny scene, and lets N simulated workers (threads
// speaking the real protocol through the real client: registration with the build fingerprint,
// long-poll leases, binary tile results, sign-off) lease and complete units as fast as the
// coordinator answers. Results are synthetic (no rendering), so the coordinator is the bottleneck.
// Prints leases/s, lease and upload latency, the coordinator's CPU time; exits non-zero if any
// leased unit was not accepted, the job's counts disagree or the coordinator ended unhealthy.
#include "farm_load.h"

#include "tessera/farm/bundle.h"
#include "tessera/farm/build_fingerprint.h"
#include "tessera/sequence/renderer.h"
#include "tessera/client/farm_api.h"

#include <CLI/CLI.hpp>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

namespace tessera::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

volatile std::sig_atomic_t g_interrupted = 0;

struct Options {
  std::string server_bin, csv;
  std::vector<std::string> server_flags;
  int workers = 64, http_threads = 64, tile_size = 32, loop_threads = 2;
  double seconds = 20, poll_wait = 2, max_poll_wait = 30, tile_seconds = 2;
  uint64_t units = 20000;
  int queued_jobs = 0;  // more jobs, of a lower priority, queued behind the measured one
};

// The smallest scene the loader takes: the coordinator loads it once at submission.
constexpr const char* kScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 0, -3" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="1"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/></film>
  </sensor>
  <shape type="rectangle"><bsdf type="diffuse"/></shape>
  <emitter type="point"><point name="position" x="0" y="0" z="-2"/><rgb name="intensity" value="1"/></emitter>
</scene>
)";

struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "tessera-farm-load-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary directory");
    path = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// Joins the simulated workers' threads on any exit path (they finish their units and sign off).
struct WorkerThreads {
  SimShared& shared;
  std::vector<std::thread> threads;
  ~WorkerThreads() {
    shared.stop = true;
    for (auto& t : threads)
      if (t.joinable()) t.join();
  }
};

// About `units` units: at most 256 tiles (a film of at most 512x512 at 32 px tiles, so the
// coordinator's memory stays small), the rest as sample passes (spp from the pass schedule:
// 1, 2, 4, ... 64, then 64 each).
struct JobShape {
  int tiles_x = 1, tiles_y = 1, passes = 1, spp = 1;
};
JobShape plan_job(uint64_t units) {
  JobShape s;
  const double tiles = double(std::min<uint64_t>(units, 256));
  s.tiles_x = int(std::ceil(std::sqrt(tiles)));
  s.tiles_y = std::max(1, int(std::lround(tiles / s.tiles_x)));
  s.passes = std::max(1, int(std::lround(double(units) / (s.tiles_x * s.tiles_y))));
  s.spp = s.passes <= 7 ? (1 << s.passes) - 1 : 127 + 64 * (s.passes - 7);
  return s;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t rank = size_t(std::ceil(q * double(v.size())));
  return v[std::min(v.size() - 1, rank > 0 ? rank - 1 : 0)];
}

// A counter's value in /metrics' text (0 when absent or unreadable).
double metric_value(const ServerProcess& server, const std::string& series) {
  const std::string text = client::FarmApi(client::FarmClient(server.url())).metrics(10).body;
  const size_t at = text.find("\n" + series + " ");
  return at == std::string::npos ? 0 : std::atof(text.c_str() + at + series.size() + 2);
}
constexpr const char* kCommits = "tessera_store_commits_total{result=\"committed\"}";

struct Figures {
  uint64_t units = 0, units_total = 0, result_bytes = 0;
  double commits = 0;  // state-database transactions (one WAL fsync each) in the measured interval
  double wall = 0, coordinator_cpu = 0, bench_cpu = 0;
  double lease_p50 = 0, lease_p99 = 0, upload_p50 = 0, upload_p99 = 0;
  uint64_t empty_polls = 0;
  double units_per_second() const { return wall > 0 ? double(units) / wall : 0; }
  double cpu_ms_per_unit() const { return units > 0 ? 1000 * coordinator_cpu / double(units) : 0; }
  double fsyncs_per_unit() const { return units > 0 ? commits / double(units) : 0; }
};

void report(const Options& o, const JobShape& shape, const Figures& f) {
  std::printf("farm load: %d simulated workers, %d HTTP threads, job of %dx%d tiles of %d px x %d passes = %llu units "
              "(%d more jobs queued behind it); %u cores shared by the coordinator and the load generator\n",
              o.workers, o.http_threads, shape.tiles_x, shape.tiles_y, o.tile_size, shape.passes,
              (unsigned long long)f.units_total, o.queued_jobs, std::thread::hardware_concurrency());
  char fed_header[32];
  std::snprintf(fed_header, sizeof(fed_header), "fed@%gs", o.tile_seconds);
  std::printf("%7s %5s %7s %7s %8s %9s %9s %10s %10s %8s %7s %8s %10s %7s %7s\n", "workers", "http", "units", "wall_s",
              "units/s", "lease_p50", "lease_p99", "upload_p50", "upload_p99", "coord_s", "coord_%", "ms/unit",
              "fsync/unit", "bench_%", fed_header);
  const double fed = f.units_per_second() * o.tile_seconds;
  std::printf("%7d %5d %7llu %7.2f %8.1f %9.2f %9.2f %10.2f %10.2f %8.2f %7.1f %8.3f %10.3f %7.1f %7.0f\n", o.workers,
              o.http_threads, (unsigned long long)f.units, f.wall, f.units_per_second(), f.lease_p50, f.lease_p99,
              f.upload_p50, f.upload_p99, f.coordinator_cpu, 100 * f.coordinator_cpu / f.wall, f.cpu_ms_per_unit(),
              f.fsyncs_per_unit(), 100 * f.bench_cpu / f.wall, fed);
  std::printf("(latencies in ms; coord_s/coord_%%: the coordinator's utime+stime over the run and as %% of one core; "
              "fsync/unit: the state database's commits per unit, one WAL fsync each; bench_%%: the load generator's own CPU; "
              "%llu empty polls; %.0f result bytes/unit)\n",
              (unsigned long long)f.empty_polls, f.units ? double(f.result_bytes) / double(f.units) : 0.0);
  std::printf("fed@%gs = units/s x %g s per tile: worker slots this coordinator kept supplied at this rate; an upper "
              "bound for real workers (they also heartbeat and fetch bundles, and a saturated coordinator has no "
              "headroom), measured while it had %.0f%% of one core",
              o.tile_seconds, o.tile_seconds, 100 * f.coordinator_cpu / f.wall);
  if (f.cpu_ms_per_unit() > 0)
    std::printf("; its CPU alone would allow %.0f units/s per core (%.0f slots)", 1000 / f.cpu_ms_per_unit(),
                o.tile_seconds * 1000 / f.cpu_ms_per_unit());
  std::printf("\n");
  if (o.csv.empty()) return;
  const bool header = !fs::exists(o.csv) || fs::file_size(o.csv) == 0;
  std::ofstream out(o.csv, std::ios::app);
  if (header)
    out << "workers,http_threads,units,wall_s,units_per_s,lease_p50_ms,lease_p99_ms,upload_p50_ms,upload_p99_ms,"
           "coord_cpu_s,coord_cpu_pct,cpu_ms_per_unit,fsync_per_unit,bench_cpu_pct,workers_fed,queued_jobs\n";
  char row[512];
  std::snprintf(row, sizeof(row), "%d,%d,%llu,%.2f,%.1f,%.2f,%.2f,%.2f,%.2f,%.2f,%.1f,%.3f,%.3f,%.1f,%.0f,%d\n", o.workers,
                o.http_threads, (unsigned long long)f.units, f.wall, f.units_per_second(), f.lease_p50, f.lease_p99,
                f.upload_p50, f.upload_p99, f.coordinator_cpu, 100 * f.coordinator_cpu / f.wall, f.cpu_ms_per_unit(),
                f.fsyncs_per_unit(), 100 * f.bench_cpu / f.wall, fed, o.queued_jobs);
  out << row;
}

// The jobs' counts summed: the measured job's, and those of the queued jobs its tail reached.
struct JobCounts {
  uint64_t done = 0, leases = 0, duplicates = 0;
  std::vector<std::string> failures;
};
JobCounts job_counts(const client::FarmApi& api, const std::vector<uint64_t>& jobs) {
  JobCounts c;
  for (uint64_t job : jobs) {
    json status = api.job(job, 10).json();
    if (!status.is_object()) {
      c.failures.push_back("no status for job " + std::to_string(job));
      continue;
    }
    const uint64_t done = status.value("units_done", uint64_t(0)), total = status.value("units_total", uint64_t(0));
    c.done += done;
    c.leases += status.value("leases_issued", uint64_t(0));
    c.duplicates += status.value("duplicate_results", uint64_t(0));
    const std::string state = status.value("state", "");
    if ((done == total) != (state == "done"))
      c.failures.push_back("job " + std::to_string(job) + " state '" + state + "' with " + std::to_string(done) + "/" +
                           std::to_string(total) + " units");
  }
  return c;
}

// Everything that must hold after a run, whatever its speed; the failures, empty if none.
std::vector<std::string> check_run(ServerProcess& server, const std::vector<uint64_t>& jobs, const std::vector<SimStats>& stats) {
  std::vector<std::string> failures;
  uint64_t leased = 0, accepted = 0, duplicates = 0;
  for (size_t i = 0; i < stats.size(); ++i) {
    const SimStats& s = stats[i];
    leased += s.leased;
    accepted += s.accepted;
    duplicates += s.duplicates;
    if (s.errors)
      failures.push_back("worker " + std::to_string(i) + ": " + std::to_string(s.errors) + " error(s), first: " +
                         s.first_error);
  }
  if (accepted != leased)
    failures.push_back(std::to_string(leased) + " units leased but " + std::to_string(accepted) + " accepted");
  if (duplicates) failures.push_back(std::to_string(duplicates) + " results acknowledged as duplicates");
  if (!server.alive()) {
    failures.push_back("the coordinator exited");
    return failures;
  }
  client::FarmApi api(client::FarmClient(server.url()));
  JobCounts c = job_counts(api, jobs);
  failures.insert(failures.end(), c.failures.begin(), c.failures.end());
  if (c.done != accepted)
    failures.push_back("the jobs count " + std::to_string(c.done) + " units done, the workers " + std::to_string(accepted));
  if (c.leases != leased)
    failures.push_back("the jobs issued " + std::to_string(c.leases) + " leases, the workers took " + std::to_string(leased));
  if (c.duplicates != 0) failures.push_back("the jobs count duplicate results");
  client::HttpReply health = api.health(10);
  if (health.status != 200 || health.json().value("status", "") != "ok")
    failures.push_back("/healthz at the end: " + health.describe() + " " + health.body);
  return failures;
}

int run(const Options& o) {
  TempDir tmp;
  ServerProcess server(o.server_bin, tmp.path.string(), o.http_threads, o.max_poll_wait, o.server_flags);
  client::FarmApi api(client::FarmClient(server.url()));

  const JobShape shape = plan_job(o.units);
  if (int(pass_schedule(uint32_t(shape.spp)).size()) != shape.passes) throw std::logic_error("pass plan");
  std::ofstream(tmp.path / "scene.xml") << kScene;
  const json settings = {{"name", "farm-load"}, {"spp", shape.spp}, {"width", shape.tiles_x * o.tile_size},
                         {"height", shape.tiles_y * o.tile_size}, {"tile_size", o.tile_size}};
  client::HttpReply submitted = api.submit_job(settings, pack_bundle(tmp.path.string(), {"scene.xml"}));
  if (submitted.status != 201) throw std::runtime_error("job submission: " + submitted.describe());
  const uint64_t job = submitted.json().value("id", uint64_t(0));
  const uint64_t units_total = submitted.json().value("units_total", uint64_t(0));
  // Queued behind it: one-unit jobs of the same bundle (by hash) at a lower priority, which the
  // scheduler must not have to look through to find the measured job's next unit.
  std::vector<uint64_t> jobs = {job};
  for (int q = 0; q < o.queued_jobs; ++q) {
    const json queued = {{"name", "queued"}, {"scene", submitted.json()["settings"]["scene"]}, {"spp", 1},
                         {"width", o.tile_size}, {"height", o.tile_size}, {"tile_size", o.tile_size}, {"priority", -1}};
    client::HttpReply r = api.submit_job(queued);
    if (r.status != 201) throw std::runtime_error("queued job submission: " + r.describe());
    jobs.push_back(r.json().value("id", uint64_t(0)));
  }

  (void)build_fingerprint();  // its probe render once, before the threads ask for it
  SimShared shared;
  shared.url = server.url();
  shared.poll_wait = o.poll_wait;
  std::vector<SimStats> stats(size_t(o.workers));
  Figures f;
  f.units_total = units_total;
  {
    WorkerThreads threads{shared, {}};
    const int loops = std::min(o.workers, o.loop_threads);
    for (int t = 0, first = 0; t < loops; ++t) {
      const int count = o.workers / loops + (t < o.workers % loops ? 1 : 0);
      threads.threads.emplace_back(run_simulated_workers, first, count, std::ref(shared), std::ref(stats));
      first += count;
    }
    for (auto end = Clock::now() + std::chrono::seconds(60); shared.registered < o.workers && Clock::now() < end &&
                                                            !g_interrupted;)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (shared.registered < o.workers) throw std::runtime_error("the workers did not register within 60 s");

    // The measured interval: from the start signal until the job is done or the time cap.
    const double commits0 = metric_value(server, kCommits);
    const double cpu0 = process_cpu_seconds(server.pid()), self0 = self_cpu_seconds();
    const auto t0 = Clock::now();
    shared.start = true;
    const auto cap = t0 + std::chrono::duration<double>(o.seconds);
    while (shared.accepted < units_total && Clock::now() < cap && !g_interrupted && server.alive())
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    f.units = shared.accepted;
    f.wall = std::chrono::duration<double>(Clock::now() - t0).count();
    f.coordinator_cpu = process_cpu_seconds(server.pid()) - cpu0;
    f.bench_cpu = self_cpu_seconds() - self0;
    f.commits = metric_value(server, kCommits) - commits0;
    shared.stop = true;
  }  // joined: every worker has finished its unit and signed off
  if (g_interrupted) return 130;

  std::vector<double> lease_ms, upload_ms;
  for (const SimStats& s : stats) {
    lease_ms.insert(lease_ms.end(), s.lease_ms.begin(), s.lease_ms.end());
    upload_ms.insert(upload_ms.end(), s.upload_ms.begin(), s.upload_ms.end());
    f.empty_polls += s.empty_polls;
  }
  f.lease_p50 = percentile(lease_ms, 0.5);
  f.lease_p99 = percentile(lease_ms, 0.99);
  f.upload_p50 = percentile(upload_ms, 0.5);
  f.upload_p99 = percentile(upload_ms, 0.99);
  std::vector<std::string> failures = check_run(server, jobs, stats);
  if (server.alive()) {
    json status = api.job(job, 10).json();
    if (status.is_object() && status.value("units_done", uint64_t(0)) > 0)
      f.result_bytes = status.value("result_bytes", uint64_t(0)) * f.units / status.value("units_done", uint64_t(1));
  }
  report(o, shape, f);
  const int stopped = server.stop();
  if (stopped != 0) failures.push_back("the coordinator did not stop cleanly on SIGTERM (status " + std::to_string(stopped) + ")");
  if (failures.empty()) return 0;
  for (const std::string& why : failures) std::fprintf(stderr, "tessera-farm-load: FAILED: %s\n", why.c_str());
  std::fprintf(stderr, "tessera-farm-load: the coordinator's log ends with:\n%s", server.log_tail(15).c_str());
  return 1;
}

}  // namespace
}  // namespace tessera::bench

int main(int argc, char** argv) {
  using tessera::bench::Options;
  Options o;
  CLI::App app{"tessera-farm-load: load benchmark of one coordinator with simulated workers on loopback"};
  app.add_option("--server-bin", o.server_bin, "the tessera-server program")->required()->check(CLI::ExistingFile);
  app.add_option("--workers", o.workers, "simulated workers")->check(CLI::Range(1, 5000))->capture_default_str();
  app.add_option("--loop-threads", o.loop_threads, "threads driving the simulated workers (an event loop each)")
      ->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--seconds", o.seconds, "cap on the measured interval")->check(CLI::Range(0.1, 600.0))->capture_default_str();
  app.add_option("--units", o.units, "work units (tiles x passes) of the job, about")
      ->check(CLI::Range(uint64_t(1), uint64_t(1000000)))->capture_default_str();
  app.add_option("--tile-size", o.tile_size, "tile edge in pixels (results of 56 bytes/pixel)")
      ->check(CLI::Range(4, 64))->capture_default_str();
  app.add_option("--http-threads", o.http_threads, "the coordinator's --http-threads")->check(CLI::Range(2, 4096))
      ->capture_default_str();
  app.add_option("--max-poll-wait", o.max_poll_wait, "the coordinator's --max-poll-wait")->check(CLI::Range(0.0, 30.0))
      ->capture_default_str();
  app.add_option("--poll-wait", o.poll_wait, "each worker's long-poll wait, seconds")->check(CLI::Range(0.0, 30.0))
      ->capture_default_str();
  app.add_option("--tile-seconds", o.tile_seconds, "render time per unit of a real worker, for the 'fed' figure")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--queued-jobs", o.queued_jobs, "jobs queued behind the measured one (lower priority, one unit each)")
      ->check(CLI::Range(0, 100000))->capture_default_str();
  app.add_option("--csv", o.csv, "append the figures as a CSV row to this file");
  app.add_option("--server-flag", o.server_flags, "another flag for tessera-server (repeatable), e.g. "
                 "--server-flag=--commit-interval=0")->allow_extra_args(false);
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, [](int) { tessera::bench::g_interrupted = 1; });
  std::signal(SIGTERM, [](int) { tessera::bench::g_interrupted = 1; });
  std::signal(SIGPIPE, SIG_IGN);
  try {
    return tessera::bench::run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera-farm-load: %s\n", e.what());
    return 2;
  }
}
