#include "tessera/worker/worker.h"

#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/tile_result.h"
#include "tessera/render/renderer.h"

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
    : opt_(resolve_worker_options(std::move(options))), client_(opt_.server, opt_.token, opt_.ca_file), cache_(opt_.cache_dir, opt_.memory_budget) {}

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
    HttpReply r = client_.post_json("/api/v1/workers", to_json(hello), 30);
    if (r.status == 201 || r.status == 200) {
      json j = r.json();
      worker_id_ = j.value("id", uint64_t(0));
      heartbeat_seconds_ = j.value("heartbeat_seconds", 5.0);
      spdlog::info("worker '{}' registered with {} as worker {} ({} threads)", opt_.name, opt_.server,
                   worker_id_.load(), opt_.threads);
      return true;
    }
    if (r.status == 409 || r.status == 400 || r.status == 401) {
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
  if (!client_.valid(&why)) {
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
  HttpReply r = client_.del("/api/v1/workers/" + std::to_string(worker_id_.load()), json::object(), 10);
  spdlog::info("worker {} signed off ({}): {} passes rendered, {} uploaded, {} duplicates, {} failures",
               worker_id_.load(), r.ok() ? "ok" : r.describe(), stats_.passes_rendered.load(),
               stats_.passes_uploaded.load(), stats_.duplicates.load(), stats_.failures.load());
  return refused_ ? 3 : 0;
}

void Worker::heartbeat_loop() {
  json leases = json::array();
  {
    std::lock_guard<std::mutex> lock(leases_mutex_);
    for (auto& [id, l] : active_) leases.push_back({{"id", id}, {"job", l.job_id}, {"tile", l.tile}, {"pass", l.pass}});
  }
  const uint64_t id = worker_id_;
  HttpReply r = client_.post_json("/api/v1/workers/" + std::to_string(id) + "/heartbeat", json{{"leases", leases}}, 10);
  if (r.status == 404) {
    std::lock_guard<std::mutex> lock(register_mutex_);
    if (worker_id_ == id) register_with_server();
    return;
  }
  json j = r.json();
  if (!r.ok() || !j.is_object() || !j.contains("drop")) return;
  std::lock_guard<std::mutex> lock(leases_mutex_);
  for (const json& d : j["drop"])
    if (d.is_number_unsigned()) dropped_[d.get<uint64_t>()] = true;
}

void Worker::slot_loop(int slot) {
  int attempt = 0;
  while (!stop_) {
    if (opt_.max_leases > 0 && leases_taken_ >= opt_.max_leases) break;
    const uint64_t id = worker_id_;
    const auto t0 = Clock::now();
    HttpReply r = client_.post_json("/api/v1/workers/" + std::to_string(id) + "/lease?wait=" +
                                        std::to_string(opt_.poll_wait),
                                    json::object(), opt_.poll_wait + 15);
    if (r.status == 404) {
      std::lock_guard<std::mutex> lock(register_mutex_);
      if (worker_id_ == id) register_with_server();
      continue;
    }
    if (r.status == 410) {  // drained by an operator: finish, sign off, exit
      spdlog::info("slot {}: the coordinator drains this worker: {}", slot, r.describe());
      stop_ = true;
      break;
    }
    if (r.status == 204) {
      attempt = 0;
      // Answered at once (the coordinator's long-poll slots are full): wait as told.
      if (Clock::now() - t0 < std::chrono::milliseconds(500)) backoff(attempt);
      attempt = 0;
      continue;
    }
    if (r.status != 200) {
      if (attempt == 0) spdlog::warn("slot {}: lease request failed: {}; retrying", slot, r.describe());
      backoff(attempt);
      continue;
    }
    attempt = 0;
    Lease lease;
    std::string error;
    if (!lease_from_json(r.json(), lease, error)) {
      spdlog::error("slot {}: bad lease from the coordinator: {}", slot, error);
      continue;
    }
    if (stop_) break;  // sign-off hands it back
    ++leases_taken_;
    process(lease);
  }
}

void Worker::process(const Lease& lease) {
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
  std::shared_ptr<const CachedScene> scene;
  try {
    scene = cache_.get(lease, client_);
  } catch (const std::exception& e) {
    finish();
    ++stats_.failures;
    spdlog::error("job {}: cannot load the scene: {}", lease.job_id, e.what());
    (void)client_.post_json("/api/v1/workers/" + std::to_string(worker_id_.load()) + "/leases/" +
                                std::to_string(lease.id) + "/fail",
                            json{{"error", e.what()}}, 10);
    return;
  }
  TileResult result = render_lease(*scene->scene, lease);
  ++stats_.passes_rendered;
  const bool dropped = finish();
  if (dropped) return;
  if (upload(lease, encode_tile_result(result))) ++stats_.passes_uploaded;
}

bool Worker::upload(const Lease& lease, const std::string& bytes) {
  // Keeps trying while the coordinator is away (a restart), for up to ten minutes.
  const auto give_up = Clock::now() + std::chrono::minutes(10);
  int attempt = 0;
  while (Clock::now() < give_up) {
    const uint64_t id = worker_id_;
    HttpReply r = client_.post_bytes("/api/v1/workers/" + std::to_string(id) + "/results?lease=" +
                                         std::to_string(lease.id),
                                     bytes, "application/x-tessera-tile", 60);
    if (r.ok()) {
      if (r.json().value("duplicate", false)) ++stats_.duplicates;
      return true;
    }
    if (r.status == 404 && r.json().value("error", "") == "unknown_worker") {
      std::lock_guard<std::mutex> lock(register_mutex_);
      if (worker_id_ == id && !register_with_server()) return false;
      continue;
    }
    if (r.status >= 400 && r.status < 500) {
      // Refused for good (job cancelled, unit no longer exists): nothing to retry.
      spdlog::info("job {} tile {} pass {}: result not taken: {}", lease.job_id, lease.tile, lease.pass, r.describe());
      return false;
    }
    if (attempt == 0) spdlog::warn("upload failed: {}; retrying", r.describe());
    backoff(attempt, /*interruptible=*/false);  // a finished pass is delivered even when stopping
  }
  return false;
}

}  // namespace tessera::farm
