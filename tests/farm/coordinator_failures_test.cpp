// The coordinator's handling of failures in-process: silent workers declared dead after missed
// heartbeats, leases of the previous process held for their workers after a restart, speculative
// copies of a job's last units with the first result winning and later ones checked against it.
#include "coordinator_fixture.h"

#include <chrono>
#include <thread>

namespace tessera::test {
namespace {

using nlohmann::json;
using server::Coordinator;

constexpr double kInterval = 0.1;  // heartbeat interval: a worker silent for 0.3 s is dead

server::CoordinatorOptions fast(const TempDir& dir, bool speculate, double interval = kInterval) {
  server::CoordinatorOptions o = options(dir);
  o.heartbeat_interval = interval;
  o.speculate = speculate;
  return o;
}

void sleep_seconds(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

std::string worker_state(Coordinator& c, uint64_t id) {
  for (const WorkerStatus& w : c.list_workers().value)
    if (w.id == id) return w.state;
  return "";
}

struct TinyScene {
  TempDir src;
  LoadResult loaded = load_scene(parse_scene_file(src.write("scene.xml", kXml)), LoadOptions{});
  const Scene& scene() const { return *loaded.scene; }
};

TEST(CoordinatorFailures, ASilentWorkerIsDeclaredDeadAndItsLeaseReissuedAtOnce) {
  TempDir dir;
  Coordinator c(fast(dir, /*speculate=*/false));
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b");
  ASSERT_TRUE(submit(c, json{{"tile_size", 8}}, bundle()).ok());
  nlohmann::json first = lease_json(c.lease(a, 0));
  ASSERT_TRUE(first.is_object());
  EXPECT_EQ(worker_state(c, a), "busy");
  // a says nothing for 3 intervals (b keeps polling); its unit must come back without waiting
  // for any longer timeout.
  const auto t0 = std::chrono::steady_clock::now();
  while (worker_state(c, a) != "lost" && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    (void)c.heartbeat(b, {});
    sleep_seconds(kInterval / 2);
  }
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(worker_state(c, a), "lost");
  EXPECT_GE(took, 3 * kInterval * 0.9);
  EXPECT_LT(took, 3 * kInterval + 3.0) << "declared dead within the heartbeat bound (plus the reaper's tick and slack)";
  nlohmann::json again = lease_json(c.lease(b, 0));
  ASSERT_TRUE(again.is_object());
  EXPECT_EQ(again["tile"], first["tile"]);
  EXPECT_EQ(again["pass"], first["pass"]);
  EXPECT_NE(c.metrics().find("tessera_workers{state=\"lost\"} 1"), std::string::npos);
  // Heard from again: live, and its late result is still taken if the unit is open.
  (void)c.heartbeat(a, {});
  EXPECT_EQ(worker_state(c, a), "idle");
}

TEST(CoordinatorFailures, AfterARestartLeasesInFlightWaitForTheirWorkers) {
  TempDir dir;
  TinyScene tiny;
  uint64_t id = 0, w = 0, v = 0;
  json held;
  {
    Coordinator c(fast(dir, false, 1.0));
    w = add_worker(c, "w");
    v = add_worker(c, "v");
    id = submit(c, json{{"tile_size", 8}, {"seed", 1}}, bundle()).value.jobs.at(0).id;
    held = lease_json(c.lease(w, 0));  // then the coordinator "dies" with this lease in flight
    ASSERT_TRUE(held.is_object());
  }
  Coordinator c(fast(dir, false, 1.0));  // held for 3 s: time for the other units
  // Another worker takes everything else, but not the held unit.
  while (deliver_one(c, v, tiny.scene(), 1)) {
  }
  json st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["units_done"].get<int>() + 1, st["units_total"].get<int>());
  // Its worker reports it and delivers it: nothing was rendered twice.
  HeldLease h{held["id"].get<uint64_t>(), held["job"].get<uint64_t>(), held["tile"].get<uint32_t>(),
              held["pass"].get<uint32_t>()};
  json hb = {{"drop", c.heartbeat(w, Heartbeat{{h}, std::nullopt}).value}};
  EXPECT_TRUE(hb["drop"].empty()) << hb.dump();
  ASSERT_TRUE(c.upload_result(w, held["id"], render_unit(held, tiny.scene(), 1)).ok());
  st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["state"], "done");
  EXPECT_EQ(st["leases_issued"], st["units_total"]) << "a unit was leased twice";
  EXPECT_EQ(st["duplicate_results"], 0);
}

TEST(CoordinatorFailures, AHeldLeaseNobodyClaimsIsReissuedAfterTheBound) {
  TempDir dir;
  json held;
  uint64_t v = 0;
  {
    Coordinator c(fast(dir, false));
    const uint64_t w = add_worker(c, "w");
    v = add_worker(c, "v");
    ASSERT_TRUE(submit(c, json{{"tile_size", 64}, {"spp", 1}}, bundle()).ok());  // one unit
    held = lease_json(c.lease(w, 0));
    ASSERT_TRUE(held.is_object());
  }
  Coordinator c(fast(dir, false));
  EXPECT_TRUE(!c.lease(v, 0).value) << "held for its worker";
  nlohmann::json l = lease_json(c.lease(v, 2.0));  // a long poll: answered once the hold runs out
  ASSERT_TRUE(l.is_object());
  EXPECT_EQ(l["tile"], held["tile"]);
}

TEST(CoordinatorFailures, IdleWorkersGetOneCopyOfTheLastUnitAndTheFirstResultWins) {
  TempDir dir;
  TinyScene tiny;
  server::CoordinatorOptions o = fast(dir, /*speculate=*/true);
  o.speculate_after = 0;
  Coordinator c(o);
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b"), d = add_worker(c, "d");
  const uint64_t id = submit(c, json{{"tile_size", 64}, {"spp", 1}, {"seed", 5}}, bundle()).value.jobs.at(0).id;
  nlohmann::json la = lease_json(c.lease(a, 0));
  ASSERT_TRUE(la.is_object());
  EXPECT_TRUE(!c.lease(a, 0).value) << "never a copy of its own lease";
  nlohmann::json lb = lease_json(c.lease(b, 0));
  ASSERT_TRUE(lb.is_object()) << "an idle worker gets a copy of the outstanding unit";
  EXPECT_EQ(lb["tile"], la["tile"]);
  EXPECT_EQ(lb["pass"], la["pass"]);
  EXPECT_NE(lb["id"], la["id"]);
  EXPECT_TRUE(!c.lease(d, 0).value) << "at most one extra copy";
  ASSERT_TRUE(c.upload_result(b, lb["id"], render_unit(lb, tiny.scene(), 5)).value.accepted);
  EXPECT_EQ(c.job_status(id).value.state, "done");
  auto late = c.upload_result(a, la["id"], render_unit(la, tiny.scene(), 5));
  ASSERT_TRUE(late.ok());
  EXPECT_TRUE(late.value.duplicate);
  json st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["duplicate_results"], 1);
  EXPECT_EQ(st["mismatched_results"], 0) << "the same unit renders the same bits";
  EXPECT_NE(c.metrics().find("tessera_passes_total{event=\"speculative\"} 1"), std::string::npos);
}

TEST(CoordinatorFailures, AUnitWhoseResultIsInIsNeverCopiedWhileItsOtherCopyIsOut) {
  TempDir dir;
  TinyScene tiny;
  server::CoordinatorOptions o = fast(dir, /*speculate=*/true, /*interval=*/2);
  o.speculate_after = 0;
  Coordinator c(o);
  std::vector<uint64_t> w;
  for (const char* name : {"a", "b", "d", "e", "f", "g", "h"}) w.push_back(add_worker(c, name));
  const uint64_t id = submit(c, json{{"tile_size", 10}, {"spp", 1}, {"seed", 5}}, bundle()).value.jobs.at(0).id;
  std::vector<json> first;
  for (int i = 0; i < 4; ++i) first.push_back(lease_json(c.lease(w[i], 0)));  // the job's 4 units
  json copy = lease_json(c.lease(w[4], 0));
  ASSERT_TRUE(copy.is_object());
  EXPECT_EQ(copy["tile"], first[0]["tile"]) << "a copy of the oldest lease";
  ASSERT_TRUE(c.upload_result(w[4], copy["id"], render_unit(copy, tiny.scene(), 5)).value.accepted);
  // The unit is in while its first lease is still out: the next idle worker gets another unit.
  json next = lease_json(c.lease(w[5], 0));
  ASSERT_TRUE(next.is_object());
  EXPECT_NE(next["tile"], first[0]["tile"]) << "an accepted unit leased again";
  json another = lease_json(c.lease(w[6], 0));
  if (another.is_object()) {
    EXPECT_NE(another["tile"], first[0]["tile"]);
  }
  for (int i = 1; i < 4; ++i) (void)c.upload_result(w[i], first[i]["id"], render_unit(first[i], tiny.scene(), 5));
  json st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["state"], "done");
  EXPECT_EQ(st["reissued_acknowledged_passes"], 0);
  EXPECT_EQ(st["max_leases_per_unit"], 2);
  EXPECT_NE(c.metrics().find("tessera_max_leases_per_unit 2"), std::string::npos);
}

TEST(CoordinatorFailures, ACopyOnlyForAnIdleWorkerAndALeaseOverTheJobsMedianUnitTime) {
  TempDir dir;
  TinyScene tiny;
  server::CoordinatorOptions o = fast(dir, /*speculate=*/true, /*interval=*/2);
  o.speculate_after = 3;
  Coordinator c(o);
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b"), d = add_worker(c, "d"), e = add_worker(c, "e");
  (void)submit(c, json{{"tile_size", 10}, {"spp", 1}, {"seed", 5}}, bundle());
  json u1 = lease_json(c.lease(a, 0));
  ASSERT_TRUE(u1.is_object());
  ASSERT_TRUE(c.upload_result(a, u1["id"], render_unit(u1, tiny.scene(), 5, /*seconds=*/1.0)).value.accepted);
  // The median unit time is 1 s: a lease is overdue after 3 s.
  json u2 = lease_json(c.lease(a, 0)), u3 = lease_json(c.lease(b, 0)), u4 = lease_json(c.lease(e, 0));
  ASSERT_TRUE(u2.is_object() && u3.is_object() && u4.is_object());
  EXPECT_FALSE(c.lease(d, 0).value.has_value()) << "no lease is overdue yet";
  sleep_seconds(3.3);
  EXPECT_FALSE(c.lease(b, 0).value.has_value()) << "a worker holding a lease is not idle";
  json copy = lease_json(c.lease(d, 0));
  ASSERT_TRUE(copy.is_object()) << "an idle worker gets a copy of an overdue unit";
  EXPECT_NE(copy["tile"], u1["tile"]);
}

TEST(CoordinatorFailures, AResultCarriesTheNextLeaseAndItsRetryIsAnsweredAsTheFirstTime) {
  TempDir dir;
  TinyScene tiny;
  Coordinator c(fast(dir, /*speculate=*/false));
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b");
  const uint64_t id = submit(c, json{{"tile_size", 8}, {"spp", 1}, {"seed", 5}}, bundle()).value.jobs.at(0).id;
  nlohmann::json first = lease_json(c.lease(a, 0));
  ASSERT_TRUE(first.is_object());
  const std::string bytes = render_unit(first, tiny.scene(), 5);
  // The answer to a result asked with `next` holds the worker's next unit, leased to it.
  json ack = to_json(c.upload_result(a, first["id"], bytes, /*next=*/true).value);
  EXPECT_TRUE(ack["accepted"].get<bool>());
  ASSERT_TRUE(ack["lease"].is_object());
  EXPECT_NE(ack["lease"]["tile"], first["tile"]);
  EXPECT_EQ(worker_state(c, a), "busy");
  // Its answer lost, the worker sends it again: accepted as the first time, not a duplicate.
  json retry = to_json(c.upload_result(a, first["id"], bytes).value);
  EXPECT_TRUE(retry["accepted"].get<bool>());
  EXPECT_FALSE(retry["duplicate"].get<bool>());
  EXPECT_EQ(c.job_status(id).value.duplicate_results, 0);
  // Another worker's copy of the same unit is a duplicate.
  EXPECT_TRUE(c.upload_result(b, 0, bytes).value.duplicate);
  EXPECT_EQ(c.job_status(id).value.duplicate_results, 1);
}

TEST(CoordinatorFailures, ALaterResultThatDiffersIsCountedAsAMismatch) {
  TempDir dir;
  TinyScene tiny;
  server::CoordinatorOptions o = fast(dir, true);
  o.speculate_after = 0;  // (a copy at once)
  Coordinator c(o);
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b");
  const uint64_t id = submit(c, json{{"tile_size", 64}, {"spp", 1}, {"seed", 5}}, bundle()).value.jobs.at(0).id;
  json la = lease_json(c.lease(a, 0)), lb = lease_json(c.lease(b, 0));
  ASSERT_TRUE(la.is_object() && lb.is_object());
  ASSERT_TRUE(c.upload_result(a, la["id"], render_unit(la, tiny.scene(), 5)).ok());
  // A broken worker: another seed gives other sums for the same unit.
  ASSERT_TRUE(c.upload_result(b, lb["id"], render_unit(lb, tiny.scene(), 6)).ok());
  json st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["duplicate_results"], 1);
  EXPECT_EQ(st["mismatched_results"], 1);
  EXPECT_NE(c.metrics().find("tessera_passes_total{event=\"mismatched\"} 1"), std::string::npos);
}

TEST(CoordinatorFailures, AnEndedJobKeepsItsPriority) {
  TempDir dir;
  Coordinator c(options(dir));
  const uint64_t id = submit(c, json{{"tile_size", 8}}, bundle()).value.jobs.at(0).id;
  ASSERT_TRUE(c.cancel_job(id).ok());
  EXPECT_EQ(c.set_priority(id, 3).code, server::Code::Conflict);
}

}  // namespace
}  // namespace tessera::test
