#include "retention.h"

#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <ctime>
#include <filesystem>
#include <set>

namespace tessera::server {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

double to_wall(fs::file_time_type t) {
  return std::chrono::duration<double>(std::chrono::file_clock::to_sys(t).time_since_epoch()).count();
}

uint64_t tree_bytes(const fs::path& dir) {
  uint64_t n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) n += it->file_size(ec);
  return n;
}

std::string utc(double t) {
  const std::time_t s = std::time_t(t);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

struct JobInfo {
  uint64_t id = 0;
  bool finished = false;
  double ended = 0;
  std::string scene;
  uint64_t bytes = 0;  // stored results + image
};

struct BundleInfo {
  uint64_t bytes = 0;  // bundle file + unpacked folder
  double last_use = 0;
  int refs = 0;  // jobs that reference it
  bool live = false;  // referenced by a queued or running job
};

}  // namespace

bool touch_bundle(const std::string& path) {
  std::error_code ec;
  fs::last_write_time(path, fs::file_time_type::clock::now(), ec);
  return !ec;
}

Status Coordinator::Impl::missing_job(uint64_t id) {
  try {
    if (std::optional<double> when = store.expired_job(id))
      return make_error(Code::NotFound, "unknown_job",
                        "job " + std::to_string(id) + " expired by retention at " + utc(*when) +
                            " (--retain-days / --retain-bytes): its results and image are deleted");
  } catch (const std::exception&) {
  }
  return unknown_job(id);
}

json Coordinator::Impl::run_retention(double now) {
  const double max_age = opt.retain_days * 86400.0;
  std::vector<JobInfo> snapshot;
  {
    std::lock_guard<std::mutex> lock(mu);
    // Images a full disk kept from being written: the job ended, its film is still in memory.
    for (auto& [id, job] : jobs)
      if (is_terminal(job->phase) && job->has_film()) finish_job(*job, /*notify=*/true);
    std::vector<uint64_t> unmeasured;
    for (auto& [id, job] : jobs)
      if (!is_terminal(job->phase) || !retention.finished_result_bytes.count(id)) unmeasured.push_back(id);
    try {
      // Once (at start-up) every job is unmeasured: one grouped query instead of one per job.
      auto sizes = unmeasured.size() == jobs.size() ? store.result_bytes() : store.result_bytes(unmeasured);
      std::map<uint64_t, uint64_t> measured(sizes.begin(), sizes.end());
      for (uint64_t id : unmeasured) {
        const bool finished = is_terminal(jobs.at(id)->phase);
        if (finished) retention.finished_result_bytes[id] = measured[id];
        else retention.finished_result_bytes.erase(id);  // (retried: measured again when it ends)
      }
      for (auto& [id, job] : jobs) {
        const bool finished = is_terminal(job->phase);
        snapshot.push_back({id, finished, job->finished > 0 ? job->finished : job->created(), job->plan().settings.scene,
                            finished ? retention.finished_result_bytes[id] : measured[id]});
      }
    } catch (const std::exception& e) {
      spdlog::warn("retention: cannot measure stored results: {}", e.what());
      return json{{"error", e.what()}};
    }
  }

  // Measure the files (outside the lock).
  std::error_code ec;
  uint64_t total = 0;
  for (JobInfo& j : snapshot) {
    const uintmax_t image = fs::file_size(image_path(j.id), ec);
    if (!ec) j.bytes += image;
    total += j.bytes;
  }
  std::map<std::string, BundleInfo> bundles;
  for (auto it = fs::directory_iterator(fs::path(opt.data_dir) / "bundles", ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    if (it->path().extension() != ".bundle") continue;
    BundleInfo& b = bundles[it->path().stem().string()];
    b.bytes += it->file_size(ec);
    b.last_use = std::max(b.last_use, to_wall(it->last_write_time(ec)));
  }
  for (auto it = fs::directory_iterator(fs::path(opt.data_dir) / "scenes", ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.find('.') != std::string::npos || !it->is_directory(ec)) continue;  // (.tmp-/.old- of an unpack in flight)
    bundles[name].bytes += tree_bytes(it->path());
  }
  for (auto& [hash, b] : bundles) total += b.bytes;
  for (const JobInfo& j : snapshot) {
    auto b = bundles.find(j.scene);
    if (b == bundles.end()) continue;
    ++b->second.refs;
    b->second.live |= !j.finished;
    if (j.finished) b->second.last_use = std::max(b->second.last_use, j.ended);
  }

  // Decide: the age limit first, then the oldest finished jobs and unused bundles until under the size.
  std::set<uint64_t> doomed_jobs;
  std::set<std::string> doomed_bundles;
  uint64_t remaining = total;
  auto drop_job = [&](const JobInfo& j) {
    doomed_jobs.insert(j.id);
    remaining -= j.bytes;
    if (auto b = bundles.find(j.scene); b != bundles.end()) --b->second.refs;
  };
  auto drop_bundle = [&](const std::string& hash) {
    doomed_bundles.insert(hash);
    remaining -= bundles[hash].bytes;
  };
  std::vector<const JobInfo*> finished;
  for (const JobInfo& j : snapshot)
    if (j.finished) finished.push_back(&j);
  std::sort(finished.begin(), finished.end(), [](const JobInfo* a, const JobInfo* b) {
    return a->ended != b->ended ? a->ended < b->ended : a->id < b->id;
  });
  if (max_age > 0) {
    for (const JobInfo* j : finished)
      if (now - j->ended > max_age) drop_job(*j);
    for (auto& [hash, b] : bundles)
      if (b.refs == 0 && now - b.last_use > max_age) drop_bundle(hash);
  }
  if (opt.retain_bytes > 0 && remaining > opt.retain_bytes) {
    size_t next_job = 0;
    while (remaining > opt.retain_bytes) {
      while (next_job < finished.size() && doomed_jobs.count(finished[next_job]->id)) ++next_job;
      const std::string* oldest_bundle = nullptr;
      for (auto& [hash, b] : bundles)
        if (!doomed_bundles.count(hash) && b.refs == 0 && now - b.last_use > kBundleGraceSeconds &&
            (!oldest_bundle || b.last_use < bundles[*oldest_bundle].last_use))
          oldest_bundle = &hash;
      const JobInfo* job = next_job < finished.size() ? finished[next_job] : nullptr;
      if (oldest_bundle && (!job || bundles[*oldest_bundle].last_use <= job->ended)) drop_bundle(*oldest_bundle);
      else if (job) drop_job(*job);
      else break;
    }
    if (remaining > opt.retain_bytes)
      spdlog::warn("retention: the data dir holds {} bytes of queued, running or recent work, over --retain-bytes {}",
                   remaining, opt.retain_bytes);
  }

  // Delete: rows under the lock, files after it.
  std::vector<std::string> doomed_files;
  std::vector<fs::path> trash;
  uint64_t deleted_jobs = 0, deleted_bundles = 0, freed = 0;
  {
    std::lock_guard<std::mutex> lock(mu);
    for (const JobInfo& j : snapshot) {
      if (!doomed_jobs.count(j.id)) continue;
      auto it = jobs.find(j.id);
      // Retried (queued again) since the snapshot: not finished any more.
      if (it == jobs.end() || !is_terminal(it->second->phase) ||
          (it->second->finished > 0 ? it->second->finished : it->second->created()) != j.ended)
        continue;
      try {
        store.delete_job(j.id, now);
      } catch (const std::exception& e) {
        spdlog::warn("retention: cannot delete job {}: {}", j.id, e.what());
        break;
      }
      end_leases_if([&](const LeaseInfo& l) { return l.job == j.id; });
      jobs.erase(it);
      retention.finished_result_bytes.erase(j.id);
      doomed_files.push_back(image_path(j.id));
      ++deleted_jobs;
      freed += j.bytes;
      log_event(spdlog::level::info, "job.expired", {{"job", j.id}, {"bytes", j.bytes}});
    }
    static std::atomic<uint64_t> trash_counter{0};
    for (const std::string& hash : doomed_bundles) {
      bool referenced = false;  // by a job submitted since the snapshot
      for (auto& [id, job] : jobs) referenced |= job->plan().settings.scene == hash;
      const fs::path file = bundle_path(hash);
      if (referenced || (fs::exists(file, ec) && to_wall(fs::last_write_time(file, ec)) > bundles[hash].last_use)) continue;
      // Renamed away under the lock: a submission finds the bundle whole or not at all.
      const std::string tag = std::to_string(::getpid()) + "-" + std::to_string(++trash_counter);
      for (const fs::path& p : {file, fs::path(scene_dir(hash))}) {
        if (!fs::exists(p, ec)) continue;
        const fs::path to = fs::path(opt.data_dir) / "tmp" / ("expired-" + tag + "-" + p.filename().string());
        fs::rename(p, to, ec);
        if (!ec) trash.push_back(to);
      }
      try {
        store.delete_scene(hash);
      } catch (const std::exception&) {
      }
      ++deleted_bundles;
      freed += bundles[hash].bytes;
      log_event(spdlog::level::info, "bundle.expired", {{"scene", hash}, {"bytes", bundles[hash].bytes}});
    }
    if (deleted_jobs > 0) try {
        store.incremental_vacuum();
      } catch (const std::exception& e) {
        spdlog::warn("retention: incremental vacuum failed: {}", e.what());
      }
    retention.deleted_jobs += deleted_jobs;
    retention.deleted_bundles += deleted_bundles;
    retention.freed_bytes += freed;
    retention.data_bytes = total >= freed ? total - freed : 0;
    ++retention.passes;
  }
  for (const std::string& f : doomed_files) fs::remove(f, ec);
  for (const fs::path& p : trash) fs::remove_all(p, ec);
  return json{{"deleted_jobs", deleted_jobs}, {"deleted_bundles", deleted_bundles}, {"freed_bytes", freed},
              {"data_bytes", total >= freed ? total - freed : 0}};
}

Result<json> Coordinator::apply_retention(double now) {
  json report = impl_->run_retention(now > 0 ? now : wall_seconds());
  if (report.contains("error")) return make_error(Code::Internal, "retention_failed", report["error"].get<std::string>());
  return report;
}

std::string retention_metrics(const RetentionState& r) {
  std::string out = metric_header("tessera_retention_deleted_total", "counter", "Finished jobs and bundles deleted by retention.");
  out += "tessera_retention_deleted_total{what=\"jobs\"} " + std::to_string(r.deleted_jobs) + "\n";
  out += "tessera_retention_deleted_total{what=\"bundles\"} " + std::to_string(r.deleted_bundles) + "\n";
  out += metric_header("tessera_retention_freed_bytes_total", "counter", "Bytes of results, images and bundles deleted by retention.");
  out += "tessera_retention_freed_bytes_total " + std::to_string(r.freed_bytes) + "\n";
  out += metric_header("tessera_retention_passes_total", "counter", "Retention passes run.");
  out += "tessera_retention_passes_total " + std::to_string(r.passes) + "\n";
  out += metric_header("tessera_data_bytes", "gauge",
                       "Stored results, images, bundles and unpacked scenes in the data dir (at the last retention pass).");
  out += "tessera_data_bytes " + std::to_string(r.data_bytes) + "\n";
  out += metric_header("tessera_disk_full_errors_total", "counter", "Requests answered 507 because the disk was full.");
  out += "tessera_disk_full_errors_total " + std::to_string(disk_full_errors()) + "\n";
  return out;
}

}  // namespace tessera::server
