// The reaper's decision (server/src/reaper.h), as a pure function: silent workers are lost and
// their leases end with them; other leases end at their own expiry.
#include "reaper.h"

#include <gtest/gtest.h>

#include <vector>

namespace tessera::test {
namespace {

using server::decide_reaping;
using server::ReapLease;
using server::ReapWorker;
using namespace std::chrono_literals;

const auto kNow = std::chrono::steady_clock::time_point{} + 1h;
constexpr auto kDeadAfter = 6s;  // 3 heartbeat intervals of 2 s

TEST(Reaper, AWorkerSilentLongerThanTheBoundIsLostAndItsLeasesEndWithIt) {
  const std::vector<ReapWorker> workers = {{1, true, kNow - 7s}, {2, true, kNow - 5s}, {3, true, kNow - 6s}};
  const std::vector<ReapLease> leases = {{10, 1, kNow + 20s}, {11, 1, kNow + 20s}, {12, 2, kNow + 20s}};
  const auto r = decide_reaping(workers, leases, kNow, kDeadAfter);
  EXPECT_EQ(r.lost_workers, std::vector<uint64_t>{1}) << "exactly at the bound is not past it";
  EXPECT_EQ(r.leases_of_lost, 2u);
  EXPECT_TRUE(r.expired_leases.empty()) << "the lost worker's leases end with it, not counted twice";
}

TEST(Reaper, OnlyLiveWorkersAreReaped) {
  const std::vector<ReapWorker> workers = {{1, false, kNow - 1h}, {2, false, kNow - 1h}};
  const std::vector<ReapLease> leases = {{10, 1, kNow + 1s}};
  const auto r = decide_reaping(workers, leases, kNow, kDeadAfter);
  EXPECT_TRUE(r.lost_workers.empty()) << "lost or signed off already";
  EXPECT_EQ(r.leases_of_lost, 0u);
  EXPECT_TRUE(r.expired_leases.empty());
}

TEST(Reaper, ALeasePastItsExpiryEndsEvenIfItsWorkerIsAlive) {
  const std::vector<ReapWorker> workers = {{1, true, kNow - 1s}};
  const std::vector<ReapLease> leases = {{10, 1, kNow - 1ms}, {11, 1, kNow}, {12, 9, kNow - 1s}};
  const auto r = decide_reaping(workers, leases, kNow, kDeadAfter);
  EXPECT_TRUE(r.lost_workers.empty());
  EXPECT_EQ(r.expired_leases, (std::vector<uint64_t>{10, 12})) << "a lease expiring now is still valid";
}

}  // namespace
}  // namespace tessera::test
