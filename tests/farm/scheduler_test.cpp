// The coordinator's choice of the next unit (server/src/scheduler.h), as a pure function.
#include "scheduler.h"

#include <gtest/gtest.h>

#include <vector>

namespace tessera::test {
namespace {

using server::choose_unit;
using server::JobCandidate;
using server::LeaseCandidate;
using server::UnitChoice;

constexpr uint64_t kWorker = 7;

// An overdue lease of `unit` held by `holder`, with `copies` in flight.
LeaseCandidate late(uint64_t job, int priority, size_t unit, uint64_t holder, unsigned copies, bool excluded = false) {
  LeaseCandidate l{job, priority, unit, holder, copies, excluded};
  l.overdue = true;
  return l;
}

std::optional<UnitChoice> choose(const std::vector<JobCandidate>& jobs, const std::vector<LeaseCandidate>& leases = {},
                                  bool speculate = true) {
  return choose_unit(jobs, leases, kWorker, speculate);
}

TEST(Scheduler, HigherPriorityFirstThenEarlierSubmission) {
  const std::vector<JobCandidate> jobs = {{1, 0, 5}, {2, 3, 9}, {3, 3, 4}, {4, 1, 0}};
  auto c = choose(jobs);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->job, 2u) << "priority 3, submitted before job 3";
  EXPECT_EQ(c->unit, 9u);
  EXPECT_FALSE(c->speculative);
}

TEST(Scheduler, JobsWithoutFreshUnitsOrThatExcludeTheWorkerAreSkipped) {
  const std::vector<JobCandidate> jobs = {{1, 5, std::nullopt}, {2, 4, 3, /*excluded=*/true}, {3, 0, 8}};
  auto c = choose(jobs, {}, /*speculate=*/false);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->job, 3u);
  EXPECT_FALSE(choose({{1, 0, std::nullopt}}, {}, false)) << "nothing to do";
}

TEST(Scheduler, AnIdleWorkerGetsACopyOfTheOldestOutstandingUnit) {
  const std::vector<JobCandidate> jobs = {{1, 0, std::nullopt}};
  // Issue order: the lease of unit 4 is the oldest.
  const std::vector<LeaseCandidate> leases = {late(1, 0, 4, 2, 1), late(1, 0, 6, 3, 1)};
  auto c = choose(jobs, leases);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->speculative);
  EXPECT_EQ(c->job, 1u);
  EXPECT_EQ(c->unit, 4u);
  EXPECT_FALSE(choose(jobs, leases, /*speculate=*/false)) << "speculation off: nothing";
}

TEST(Scheduler, NeverACopyOfItsOwnLeaseNorAThirdCopy) {
  const std::vector<JobCandidate> jobs = {{1, 0, std::nullopt}};
  EXPECT_FALSE(choose(jobs, {late(1, 0, 4, kWorker, 1)})) << "the worker's own lease";
  EXPECT_FALSE(choose(jobs, {late(1, 0, 4, 2, 2), late(1, 0, 4, 3, 2)})) << "already two copies in flight";
  EXPECT_FALSE(choose(jobs, {late(1, 0, 4, 2, 1, /*excluded=*/true)})) << "a job the worker is kept off";
  auto c = choose(jobs, {late(1, 0, 4, kWorker, 1), late(1, 0, 5, 2, 2), late(1, 0, 6, 2, 1)});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->unit, 6u);
}

TEST(Scheduler, FreshWorkOfEqualPriorityBeatsASpeculativeCopy) {
  const std::vector<LeaseCandidate> leases = {late(1, 2, 4, 2, 1)};
  auto same = choose({{1, 2, std::nullopt}, {2, 2, 11}}, leases);
  ASSERT_TRUE(same);
  EXPECT_EQ(same->job, 2u);
  EXPECT_FALSE(same->speculative);
  // A job of higher priority waiting on its last unit is helped before a lower one's fresh work.
  auto higher = choose({{1, 2, std::nullopt}, {2, 1, 11}}, leases);
  ASSERT_TRUE(higher);
  EXPECT_EQ(higher->job, 1u);
  EXPECT_TRUE(higher->speculative);
  EXPECT_EQ(server::speculation_floor(std::vector<JobCandidate>{{1, 2, std::nullopt}, {2, 1, 11}}), 1);
}

TEST(Scheduler, NeverACopyOfAFinishedUnitNorOfALeaseNotYetOverdue) {
  const std::vector<JobCandidate> jobs = {{1, 0, std::nullopt}};
  // The unit's accepted copy ended its lease; the other copy's lease is still in flight.
  LeaseCandidate finished = late(1, 0, 4, 2, 1);
  finished.finished = true;
  EXPECT_FALSE(choose(jobs, {finished})) << "an accepted unit is never leased again";
  LeaseCandidate young = late(1, 0, 6, 3, 1);
  young.overdue = false;
  EXPECT_FALSE(choose(jobs, {young})) << "a lease within its job's threshold";
  auto c = choose(jobs, {finished, young, late(1, 0, 8, 3, 1)});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->unit, 8u) << "the oldest lease that is overdue and not finished";
}

}  // namespace
}  // namespace tessera::test
