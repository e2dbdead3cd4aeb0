// Retention's decision (server/src/retention_plan.h) as a pure function: the age limit, the size
// limit taking the oldest finished job or unused bundle first, and what is never deleted.
#include "retention_plan.h"

#include <gtest/gtest.h>

namespace tessera::server {
namespace {

constexpr double kDay = 86400;
constexpr double kNow = 100 * kDay;

RetentionJob finished(uint64_t id, double ended, const std::string& scene, uint64_t bytes) {
  return {id, true, ended, scene, bytes};
}
RetentionJob running(uint64_t id, const std::string& scene, uint64_t bytes) { return {id, false, kNow - kDay, scene, bytes}; }

TEST(RetentionPlan, NoLimitsDeleteNothing) {
  const RetentionPlan plan = plan_retention({finished(1, 0, "a", 10)}, {{"a", {5, 0}}}, {}, kNow);
  EXPECT_TRUE(plan.jobs.empty());
  EXPECT_TRUE(plan.bundles.empty());
  EXPECT_EQ(plan.total, 15u);
  EXPECT_EQ(plan.remaining, 15u);
}

TEST(RetentionPlan, TheAgeLimitTakesOldFinishedJobsAndBundlesNothingUses) {
  const std::vector<RetentionJob> jobs = {finished(1, kNow - 10 * kDay, "a", 100), finished(2, kNow - 1 * kDay, "b", 100),
                                          finished(3, kNow - 9 * kDay, "b", 100), running(4, "c", 100)};
  const std::map<std::string, RetentionBundle> bundles = {
      {"a", {10, kNow - 20 * kDay}}, {"b", {10, kNow - 20 * kDay}}, {"c", {10, kNow - 20 * kDay}}, {"d", {10, kNow - 8 * kDay}}};
  const RetentionPlan plan = plan_retention(jobs, bundles, {7 * kDay, 0, 600}, kNow);
  EXPECT_EQ(plan.jobs, (std::vector<uint64_t>{1, 3}));  // oldest first; job 2 ended a day ago
  // a: its only job goes; b: job 2 still uses it; c: a running job uses it; d: unused for 8 days.
  EXPECT_EQ(plan.bundles, (std::vector<std::string>{"a", "d"}));
  EXPECT_EQ(plan.remaining, plan.total - 200 - 20);
}

TEST(RetentionPlan, TheSizeLimitTakesTheOldestFirstAndStopsWhenUnder) {
  const std::vector<RetentionJob> jobs = {finished(5, kNow - 3 * kDay, "a", 100), finished(6, kNow - 5 * kDay, "a", 100),
                                          finished(7, kNow - 4 * kDay, "a", 100), running(8, "b", 100)};
  const std::map<std::string, RetentionBundle> bundles = {{"a", {50, kNow - 6 * kDay}}, {"b", {50, kNow - 9 * kDay}},
                                                          {"old", {50, kNow - 4.5 * kDay}}};
  // 550 bytes, limit 320: job 6 (5 days), the unused bundle "old" (4.5 days), job 7 (4 days): 320.
  const RetentionPlan plan = plan_retention(jobs, bundles, {0, 320, 600}, kNow);
  EXPECT_EQ(plan.jobs, (std::vector<uint64_t>{6, 7}));
  EXPECT_EQ(plan.bundles, (std::vector<std::string>{"old"}));
  EXPECT_EQ(plan.total, 550u);
  EXPECT_EQ(plan.remaining, 300u);
}

TEST(RetentionPlan, QueuedRunningAndRecentWorkIsKeptEvenOverTheLimit) {
  const std::vector<RetentionJob> jobs = {running(1, "a", 1000)};
  const std::map<std::string, RetentionBundle> bundles = {{"a", {100, 0}}, {"fresh", {100, kNow - 60}}};
  const RetentionPlan plan = plan_retention(jobs, bundles, {kDay, 10, 600}, kNow);
  EXPECT_TRUE(plan.jobs.empty());
  EXPECT_TRUE(plan.bundles.empty()) << "a running job's bundle, and one uploaded a minute ago, stay";
  EXPECT_EQ(plan.remaining, 1200u);
}

TEST(RetentionPlan, ABundleWhoseLastJobGoesIsDeletedInTheSamePass) {
  const std::vector<RetentionJob> jobs = {finished(1, kNow - 2 * kDay, "a", 100)};
  const std::map<std::string, RetentionBundle> bundles = {{"a", {100, kNow - 3 * kDay}}};
  const RetentionPlan plan = plan_retention(jobs, bundles, {0, 50, 600}, kNow);
  EXPECT_EQ(plan.jobs, (std::vector<uint64_t>{1}));
  EXPECT_EQ(plan.bundles, (std::vector<std::string>{"a"}));
  EXPECT_EQ(plan.remaining, 0u);
}

}  // namespace
}  // namespace tessera::server
