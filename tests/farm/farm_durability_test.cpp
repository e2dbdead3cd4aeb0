// Durability under load: simulated workers (threads of this test, rendering their units for real
// with the worker's render_lease) lease and upload as fast as they can while the coordinator is
// killed with SIGKILL at random moments and restarted. After each restart, every result the
// coordinator had acknowledged is still there (delivering it again is answered as a duplicate),
// and the finished image is bit-identical to a local render.
#include "farm_harness.h"

#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/tile_result.h"

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <random>
#include <set>

namespace tessera::test {
namespace {

// Many small units: 128x96 in 8-pixel tiles (192 tiles) x 6 passes (37 spp) = 1152 units.
JobSettings many_units() {
  JobSettings s;
  s.name = "durability";
  s.spp = 37;
  s.width = 128;
  s.height = 96;
  s.tile_size = 8;
  s.seed = 5;
  return s;
}

// What the workers were told: the encoded result of every unit the coordinator acknowledged.
struct Acknowledged {
  std::mutex mu;
  std::map<std::pair<uint32_t, uint32_t>, std::string> results;  // (tile, pass) -> result bytes
  void add(const Lease& l, const std::string& bytes) {
    std::lock_guard<std::mutex> lock(mu);
    results.emplace(std::make_pair(l.tile, l.pass), bytes);
  }
  auto snapshot() {
    std::lock_guard<std::mutex> lock(mu);
    return results;
  }
};

// A worker that keeps going through coordinator restarts: failed requests are retried until they
// are answered, as tessera-worker does.
struct Control {
  std::atomic<bool> stop{false}, paused{false};  // paused: while the test checks a restart
  std::atomic<int> errors{0};
};

void simulated_worker(const Farm& farm, const Scene& scene, int index, Control& control, Acknowledged& acked) {
  std::atomic<bool>& stop = control.stop;
  client::FarmApi api = farm.api();
  const BuildFingerprint& fp = build_fingerprint();
  uint64_t id = 0;
  while (id == 0 && !stop) {
    const WorkerHello hello{"sim-" + std::to_string(index), 1, uint64_t(1) << 30, fp.version, fp.isa, fp.probe};
    auto reg = api.register_worker(hello);
    if (reg.ok()) id = reg.value.id;
    else std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::optional<Lease> lease;
  while (!stop) {
    if (control.paused) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    if (!lease) {
      auto r = api.lease(id, 1, 10);
      if (r.ok()) lease = std::move(r.value);
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    const std::string bytes = encode_tile_result(render_lease(scene, *lease));
    for (;;) {  // delivered even if the coordinator dies meanwhile
      auto r = api.upload_result(id, lease->id, bytes, 10, /*want_next=*/index % 2 == 0);
      if (r.ok()) {
        acked.add(*lease, bytes);
        lease = std::move(r.value.next);
        break;
      }
      if (r.http.status != 0 && r.http.status < 500) {
        ++control.errors;
        ADD_FAILURE() << "upload refused: " << r.describe();
        lease.reset();
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

TEST(FarmDurability, AcknowledgedResultsSurviveKillsUnderLoadAndTheImageIsBitExact) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm({"--heartbeat-interval", "0.2"});
  farm.start_server();
  const JobSettings settings = many_units();
  const uint64_t id = farm.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  auto abs = std::filesystem::absolute(cornell());
  JobSettings worker_settings = settings;
  LoadedJobScene loaded = load_job_scene(abs.parent_path().string(), abs.filename().string(), worker_settings, false);

  Acknowledged acked;
  Control control;
  std::vector<std::thread> workers;
  for (int i = 0; i < 6; ++i)
    workers.emplace_back(simulated_worker, std::cref(farm), std::cref(*loaded.loaded.scene), i, std::ref(control),
                         std::ref(acked));

  // Killed at four random points of the job's progress (at random moments, but always mid-job).
  const unsigned seed = std::random_device{}();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> point(0.05, 0.85);
  std::vector<double> points = {point(rng), point(rng), point(rng), point(rng)};
  std::sort(points.begin(), points.end());
  int kills = 0;
  size_t checked = 0;
  for (double at : points) {
    nlohmann::json now = farm.wait_until(id, [at](const nlohmann::json& j) { return j.value("progress", 0.0) >= at; });
    if (now.value("state", "") == "done") break;
    farm.kill_server();  // SIGKILL, with uploads in flight
    ++kills;
    const auto before = acked.snapshot();
    farm.start_server();
    control.paused = true;
    // Every result acknowledged before the kill is still there: delivered again by another worker
    // (its own worker's retry would be answered as the first time), it is a duplicate.
    client::FarmApi api = farm.api();
    const BuildFingerprint& fp = build_fingerprint();
    auto checker = api.register_worker(WorkerHello{"checker", 1, uint64_t(1) << 30, fp.version, fp.isa, fp.probe});
    ASSERT_TRUE(checker.ok()) << checker.describe();
    for (const auto& [unit, bytes] : before) {
      auto r = api.upload_result(checker.value.id, 0, bytes, 10);
      ASSERT_TRUE(r.ok()) << r.describe();
      EXPECT_TRUE(r.value.duplicate) << "tile " << unit.first << " pass " << unit.second
                                     << " was acknowledged before the kill but is missing after it (seed " << seed << ")";
    }
    checked += before.size();
    control.paused = false;
  }
  nlohmann::json st = farm.wait_job(id, 300);
  control.stop = true;
  for (auto& t : workers) t.join();
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  EXPECT_EQ(control.errors.load(), 0);
  EXPECT_GE(kills, 3) << "the job finished before the coordinator could be killed three times";
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), settings)), 0) << "seed " << seed;
  std::printf("%d kills (seed %u): %zu acknowledged results re-checked after restarts; %d units\n", kills, seed,
              checked, st.value("units_total", 0));
}

}  // namespace
}  // namespace tessera::test
