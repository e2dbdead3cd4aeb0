#include "tessera/worker/worker.h"

#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/tile_result.h"
#include "tessera/sequence/renderer.h"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

namespace tessera::farm {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

WorkerOptions resolve_worker_options(WorkerOptions o) {
  if (o.threads <= 0) o.threads = std::max(1, int(std::thread::hardware_concurrency()));
  if (o.name.empty()) {
    char host[256] = {};
    o.name = gethostname(host, sizeof(host) - 1) == 0 ? host : "worker";
  }
  if (o.cache_dir.empty()) {
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    o.cache_dir = xdg && *xdg ? std::string(xdg) + "/tessera-worker"
                  : home      ? std::string(home) + "/.cache/tessera-worker"
                              : "/tmp/tessera-worker";
  }
  if (o.memory_budget == 0) o.memory_budget = uint64_t(sysconf(_SC_PHYS_PAGES)) * uint64_t(sysconf(_SC_PAGESIZE)) / 2;
  return o;
}

Worker::Worker(WorkerOptions options)
    : opt_(resolve_worker_options(std::move(options))), api_(client::FarmClient(opt_.server, opt_.token, opt_.ca_file)), cache_lock_(opt_.cache_dir), cache_(opt_.cache_dir, opt_.memory_budget) {}

void Worker::backoff(int& attempt, bool interruptible) {
  // 0.25 s doubling to 8 s, in small steps so a stop request is seen at once.
  const double seconds = std::min(8.0, 0.25 * double(1 << std::min(attempt, 5)));
  ++attempt;
  for (auto end = Clock::now() + std::chrono::duration<double>(seconds); Clock::now() < end && !(interruptible && stop_);)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

bool Worker::register_with_server() {
  const BuildFingerprint& fp = build_fingerprint();
  WorkerHello hello{opt_.name, opt_.threads, opt_.memory_budget, fp.version, fp.isa, fp.probe};
  for (int attempt = 0; !stop_;) {
    client::ApiReply<client::Registration> r = api_.register_worker(hello);
    if (r.ok()) {
      worker_id_ = r.value.id;
      heartbeat_seconds_ = r.value.heartbeat_seconds;
      spdlog::info("worker '{}' registered with {} as worker {} ({} threads)", opt_.name, opt_.server,
                   worker_id_.load(), opt_.threads);
      return true;
    }
    if (r.http.status == 409 || r.http.status == 400 || r.http.status == 401) {
      spdlog::error("the coordinator refused this worker: {}", r.describe());
      refused_ = true;
      stop_ = true;
      return false;
    }
    if (attempt == 0 || attempt % 10 == 0) spdlog::warn("cannot register with {}: {}; retrying", opt_.server, r.describe());
    backoff(attempt);
  }
  return false;
}

int Worker::run() {
  std::string why;
  if (!api_.valid(&why)) {
    spdlog::error("{}", why);
    return 2;
  }
  if (!register_with_server()) return refused_ ? 3 : 0;
  std::vector<std::thread> slots;
  for (int i = 0; i < opt_.threads; ++i) slots.emplace_back([this, i] { slot_loop(i); });
  std::atomic<bool> slots_done{false};
  std::thread heartbeat([this, &slots_done] {
    while (!slots_done) {
      for (auto end = Clock::now() + std::chrono::duration<double>(heartbeat_seconds_.load());
           Clock::now() < end && !slots_done;)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (!slots_done) heartbeat_loop();
    }
  });
  for (auto& t : slots) t.join();
  slots_done = true;
  heartbeat.join();
  // Sign off: the coordinator re-issues anything still leased to us at once.
  client::HttpReply r = api_.sign_off(worker_id_.load());
  spdlog::info("worker {} signed off ({}): {} passes rendered, {} uploaded, {} duplicates, {} failures",
               worker_id_.load(), r.ok() ? "ok" : r.describe(), stats_.passes_rendered.load(),
               stats_.passes_uploaded.load(), stats_.duplicates.load(), stats_.failures.load());
  return refused_ ? 3 : 0;
}

void Worker::heartbeat_loop() {
  Heartbeat beat;
  {
    std::lock_guard<std::mutex> lock(leases_mutex_);
    for (auto& [id, l] : active_) beat.leases.push_back({id, l.job_id, l.tile, l.pass});
  }
  beat.memory = cache_.memory();
  const uint64_t id = worker_id_;
  client::ApiReply<std::vector<uint64_t>> r = api_.heartbeat(id, beat);
  if (r.http.status == 404) {
    std::lock_guard<std::mutex> lock(register_mutex_);
    if (worker_id_ == id) register_with_server();
    return;
  }
  if (!r.ok()) return;
  std::lock_guard<std::mutex> lock(leases_mutex_);
  for (uint64_t d : r.value) dropped_[d] = true;
}

void Worker::slot_loop(int slot) {
  int attempt = 0;
  std::optional<Lease> next;  // handed out with the previous result
  while (!stop_) {
    if (next) {
      const Lease lease = std::move(*next);
      next = process(lease);
      continue;
    }
    if (!wants_more()) break;
    const uint64_t id = worker_id_;
    const auto t0 = Clock::now();
    client::ApiReply<std::optional<Lease>> r = api_.lease(id, opt_.poll_wait, opt_.poll_wait + 15);
    if (r.http.status == 404) {
      std::lock_guard<std::mutex> lock(register_mutex_);
      if (worker_id_ == id) register_with_server();
      continue;
    }
    if (r.http.status == 410) {  // drained by an operator: finish, sign off, exit
      spdlog::info("slot {}: the coordinator drains this worker: {}", slot, r.describe());
      stop_ = true;
      break;
    }
    if (r.ok() && !r.value) {
      attempt = 0;
      // Answered at once (the coordinator's long-poll slots are full): wait as told.
      if (Clock::now() - t0 < std::chrono::milliseconds(500)) backoff(attempt);
      attempt = 0;
      continue;
    }
    if (!r.error.empty()) {
      spdlog::error("slot {}: {}", slot, r.error);
      continue;
    }
    if (!r.ok()) {
      if (attempt == 0) spdlog::warn("slot {}: lease request failed: {}; retrying", slot, r.describe());
      backoff(attempt);
      continue;
    }
    attempt = 0;
    if (stop_) break;  // sign-off hands it back
    ++leases_taken_;
    next = process(*r.value);
  }
}

std::optional<Lease> Worker::process(const Lease& lease) {
  {
    std::lock_guard<std::mutex> lock(leases_mutex_);
    active_[lease.id] = lease;
  }
  auto finish = [&] {
    std::lock_guard<std::mutex> lock(leases_mutex_);
    active_.erase(lease.id);
    bool dropped = dropped_.count(lease.id) > 0;
    dropped_.erase(lease.id);
    return dropped;
  };
  std::shared_ptr<const CachedScene> scene, guide;
  std::string bytes;
  try {
    scene = cache_.get(lease, api_);
    if (lease.guide) guide = cache_.guide(lease, api_, *scene->scene);
    bytes = render(*scene->scene, lease, guide.get());
  } catch (const std::exception& e) {  // (a scene that does not load, a unit this build cannot render)
    finish();
    ++stats_.failures;
    spdlog::error("job {}: cannot render tile {} of pass {}: {}", lease.job_id, lease.tile, lease.pass, e.what());
    (void)api_.fail_lease(worker_id_.load(), lease.id, e.what());
    return std::nullopt;
  }
  ++stats_.passes_rendered;
  const bool dropped = finish();
  if (dropped) return std::nullopt;
  std::optional<client::ResultAck> ack = upload(lease, bytes);
  if (!ack) return std::nullopt;
  ++stats_.passes_uploaded;
  if (ack->next) ++leases_taken_;
  return std::move(ack->next);
}

std::string Worker::render(const Scene& scene, const Lease& lease, const CachedScene* artifact) {
  if (uses_light_vertex_passes(scene.integrator.type))
    return lease.paths ? encode_splat_result(render_light_vertex_paths(scene, lease))
                       : encode_tile_result(render_light_vertex_tile(scene, lease, artifact ? artifact->points.get() : nullptr));
  return lease.paths ? encode_splat_result(render_paths_lease(scene, lease))
                     : encode_tile_result(render_lease(scene, lease, artifact ? artifact->guide.get() : nullptr));
}

std::optional<client::ResultAck> Worker::upload(const Lease& lease, const std::string& bytes) {
  // Keeps trying while the coordinator is away (a restart), for up to ten minutes.
  const auto give_up = Clock::now() + std::chrono::minutes(10);
  int attempt = 0;
  while (Clock::now() < give_up) {
    const uint64_t id = worker_id_;
    client::ApiReply<client::ResultAck> r = api_.upload_result(id, lease.id, bytes, 60, wants_more());
    if (r.ok()) {
      if (r.value.duplicate) ++stats_.duplicates;
      return std::move(r.value);
    }
    if (r.http.status == 404 && r.http.json().value("error", "") == "unknown_worker") {
      std::lock_guard<std::mutex> lock(register_mutex_);
      if (worker_id_ == id && !register_with_server()) return std::nullopt;
      continue;
    }
    if (r.http.status >= 400 && r.http.status < 500) {
      // Refused for good (job cancelled, unit no longer exists): nothing to retry.
      spdlog::info("job {} tile {} pass {}: result not taken: {}", lease.job_id, lease.tile, lease.pass, r.describe());
      return std::nullopt;
    }
    if (attempt == 0) spdlog::warn("upload failed: {}; retrying", r.describe());
    backoff(attempt, /*interruptible=*/false);  // a finished pass is delivered even when stopping
  }
  return std::nullopt;
}

}  // namespace tessera::farm
