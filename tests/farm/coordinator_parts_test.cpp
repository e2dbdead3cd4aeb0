// The coordinator's parts on their own (server/src/job_registry.h, lease_table.h,
// worker_registry.h, farm_metrics.h): each keeps its invariants whatever is done to it.
#include "farm_metrics.h"
#include "job_registry.h"
#include "lease_table.h"
#include "worker_registry.h"

#include <gtest/gtest.h>

#include <random>

namespace tessera::test {
namespace {

using namespace tessera::server;

// A job of 2 x 1 tiles and 3 passes (1, 2, 1 samples): 6 units.
std::unique_ptr<JobState> small_job(uint64_t id, int priority) {
  JobPlan plan;
  plan.settings.spp = 4;
  plan.settings.tile_size = 4;
  plan.window = {0, 0, 8, 4};
  plan.full_width = 8;
  plan.full_height = 4;
  return std::make_unique<JobState>(id, plan, "job", priority, 0);
}

TEST(JobRegistry, ServesActiveJobsByPriorityThenSubmission) {
  JobRegistry jobs;
  for (auto [id, priority] : {std::pair{1, 0}, {2, 5}, {3, 5}, {4, 1}}) jobs.add(small_job(uint64_t(id), priority));
  auto none = [](const JobState&) { return false; };
  std::vector<JobCandidate> c = jobs.candidates(none);
  ASSERT_EQ(c.size(), 1u) << "the first job with a fresh unit ends the list";
  EXPECT_EQ(c[0].job, 2u);
  // Job 2 barred for this worker: job 3 is next.
  c = jobs.candidates([](const JobState& j) { return j.id() == 2; });
  ASSERT_EQ(c.size(), 2u);
  EXPECT_TRUE(c[0].excluded);
  EXPECT_EQ(c[1].job, 3u);
  // A new priority moves a job; an ended job leaves the order (and the count of active jobs).
  jobs.set_priority(*jobs.find(1), 9);
  EXPECT_EQ(jobs.candidates(none)[0].job, 1u);
  jobs.set_phase(*jobs.find(1), JobPhase::Cancelled);
  EXPECT_EQ(jobs.candidates(none)[0].job, 2u);
  EXPECT_EQ(jobs.active(), 3u);
  EXPECT_EQ(jobs.count_by_phase().at("cancelled"), 1);
  jobs.set_phase(*jobs.find(1), JobPhase::Queued);  // retried
  EXPECT_EQ(jobs.candidates(none)[0].job, 1u);
  // A rebuilt job in place of its old self keeps one entry; an erased one is gone.
  jobs.replace(small_job(3, 7));
  EXPECT_EQ(jobs.active(), 4u);
  EXPECT_EQ(jobs.candidates(none)[0].job, 1u) << "9 beats 7";
  jobs.erase(1);
  EXPECT_EQ(jobs.candidates(none)[0].job, 3u);
  EXPECT_EQ(jobs.size(), 3u);
  EXPECT_EQ(jobs.active(), 3u);
}

TEST(JobRegistry, ALeasedJobHandsOutItsOtherUnitsThenNone) {
  JobRegistry jobs;
  JobState& job = jobs.add(small_job(1, 0));
  auto none = [](const JobState&) { return false; };
  std::vector<size_t> leased;
  for (auto c = jobs.candidates(none); !c.empty() && c[0].fresh_unit; c = jobs.candidates(none)) {
    leased.push_back(*c[0].fresh_unit);
    job.lease_started(*c[0].fresh_unit);
  }
  EXPECT_EQ(leased, (std::vector<size_t>{0, 1, 2, 3, 4, 5})) << "pass-major, every unit once";
  job.lease_ended(3);  // (its worker died: the unit is handed back first)
  EXPECT_EQ(jobs.candidates(none)[0].fresh_unit, 3u);
}

TEST(JobRegistry, SubmissionSlotsCountAgainstTheLimit) {
  JobRegistry jobs;
  jobs.add(small_job(1, 0));
  EXPECT_TRUE(jobs.check_active(2).ok());
  jobs.take_slot();
  const Status full = jobs.check_active(2);
  EXPECT_EQ(full.code, Code::TooManyRequests);
  EXPECT_NE(full.detail.find("the limit is 2"), std::string::npos) << full.detail;
  jobs.give_back_slot();
  EXPECT_TRUE(jobs.check_active(2).ok());
}

TEST(LeaseTable, HeldCountsAndJobIndexFollowEveryChange) {
  LeaseTable leases(100);
  EXPECT_EQ(leases.next_id(), 101u) << "ids continue after the last one logged";
  std::mt19937 rng(3);
  std::map<uint64_t, LeaseInfo> model;
  for (int step = 0; step < 2000; ++step) {
    const uint64_t id = 1 + rng() % 40;
    if (rng() % 3 == 0) {
      EXPECT_EQ(leases.end(id).has_value(), model.erase(id) > 0);
    } else {
      const LeaseInfo l{id, 1 + rng() % 4, 1 + rng() % 5, size_t(rng() % 9), Clock::now(), Clock::now()};
      leases.add(l);  // (replaces a lease of the same id)
      model[id] = l;
    }
    ASSERT_EQ(leases.size(), model.size());
  }
  for (uint64_t w = 1; w <= 5; ++w) {
    std::vector<uint64_t> expect;
    for (auto& [id, l] : model)
      if (l.worker == w) expect.push_back(id);
    EXPECT_EQ(leases.of_worker(w), expect);
    EXPECT_EQ(leases.holds(w), !expect.empty());
  }
  for (uint64_t j = 1; j <= 4; ++j) {
    std::vector<uint64_t> expect;
    for (auto& [id, l] : model)
      if (l.job == j) expect.push_back(id);
    EXPECT_EQ(leases.of_job(j), expect) << "oldest first";
    for (size_t u = 0; u < 9; ++u) {
      std::vector<uint64_t> of_unit;
      for (uint64_t id : expect)
        if (model[id].unit == u) of_unit.push_back(id);
      EXPECT_EQ(leases.of_unit(j, u), of_unit);
    }
  }
  EXPECT_GT(leases.next_id(), 101u);
  for (uint64_t id : leases.of_worker(1)) ASSERT_TRUE(leases.end(id));
  EXPECT_FALSE(leases.holds(1)) << "a worker whose leases all ended holds none";
}

TEST(WorkerRegistry, StatesChangeInOnePlaceAndGoneIsFinal) {
  WorkerRegistry workers(/*registered_before=*/3);
  EXPECT_TRUE(workers.needs_adoption(2)) << "an earlier process's worker";
  EXPECT_FALSE(workers.needs_adoption(4));
  EXPECT_FALSE(workers.needs_adoption(0));
  EXPECT_TRUE(workers.adopt(WorkerRow{2, "old"}));
  EXPECT_FALSE(workers.adopt(WorkerRow{2, "old"})) << "adopted once";
  WorkerInfo& w = workers.add(WorkerRow{4, "new"});
  EXPECT_EQ(workers.live(), 2u);
  auto change = workers.set_state(w, WorkerState::Lost);
  ASSERT_TRUE(change);
  EXPECT_EQ(change->from, WorkerState::Idle);
  EXPECT_FALSE(workers.set_state(w, WorkerState::Lost)) << "no change to the same state";
  EXPECT_EQ(workers.live(), 1u);
  ASSERT_TRUE(workers.set_state(w, WorkerState::Gone));
  EXPECT_FALSE(workers.set_state(w, WorkerState::Idle)) << "signing off is final";
  EXPECT_EQ(workers.count_by_state().at("gone"), 1);
  EXPECT_EQ(workers.count_by_state().at("idle"), 1);
}

TEST(FarmMetrics, RendersCountersAndTheSnapshot) {
  FarmMetrics metrics;
  metrics.counters.leased += 7;
  metrics.counters.bytes_out += 1234;
  metrics.lease_wait.observe(0.2);
  MetricsSnapshot s;
  s.jobs_by_phase = {{"queued", 2}, {"running", 1}};
  s.workers_by_state = {{"idle", 1}};
  s.workers = {{3, "a \"quoted\" name", 12.5, 1000}};
  s.leases_active = 4;
  const std::string text = metrics.render(s);
  for (const char* line : {"tessera_jobs{state=\"queued\"} 2", "tessera_passes_total{event=\"leased\"} 7",
                           "tessera_leases_active 4", "tessera_bytes_total{direction=\"out\"} 1234",
                           "tessera_worker_samples_per_second{worker=\"3\",name=\"a \\\"quoted\\\" name\"} 12.5",
                           "tessera_lease_wait_seconds_count 1"})
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
}

}  // namespace
}  // namespace tessera::test
