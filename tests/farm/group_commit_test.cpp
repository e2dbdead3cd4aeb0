// The coordinator's group commit (server/src/group_commit.h): records are applied in append order,
// many to one transaction, a failed batch fails each of its tickets and keeps only the records
// marked for retry, and what was appended is durable once the writer stops.
#include "group_commit.h"

#include "tessera/server/store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <future>
#include <thread>

namespace tessera::server {
namespace {

namespace fs = std::filesystem;

struct TempDb {
  fs::path dir = fs::temp_directory_path() / ("tessera-group-commit-" + std::to_string(::getpid()) + "-" +
                                              std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  TempDb() { fs::create_directories(dir); }
  ~TempDb() { fs::remove_all(dir); }
  std::string path() const { return (dir / "state.sqlite").string(); }
};

GroupCommit::Write lease_record(uint64_t seq) {
  return [seq](Store& st) { st.log_lease(seq, 1, uint32_t(seq), 0, 7, 0.0); };
}

// A record that holds the writer inside its transaction until released; append() returns once
// the writer is in it, so what is appended next waits for the following batch.
class Blocker {
 public:
  uint64_t append(GroupCommit& commits, GroupCommit::Write also = [](Store&) {}) {
    const uint64_t ticket = commits.append([this, also](Store& st) {
      entered_.set_value();
      released_.wait();
      also(st);
    });
    entered_.get_future().wait();
    return ticket;
  }
  void release() { release_.set_value(); }

 private:
  std::promise<void> entered_, release_;
  std::shared_future<void> released_ = release_.get_future().share();
};

TEST(GroupCommit, RecordsAppendedWhileABatchCommitsShareTheNextTransaction) {
  TempDb db;
  Store store(db.path());
  int runs = 0;  // the runner is called once per batch (the coordinator takes its lock there)
  GroupCommit commits(store, [&runs](const std::function<void()>& callbacks) {
    ++runs;
    callbacks();
  });
  // The first record holds the writer inside its transaction until 99 more are queued.
  Blocker blocker;
  uint64_t last = blocker.append(commits, lease_record(1));
  std::vector<int> told(101, 0);
  for (uint64_t seq = 2; seq <= 100; ++seq)
    last = commits.append(lease_record(seq), GroupCommit::Retry::No, [&told, seq](bool ok) { told[seq] += ok ? 1 : -100; });
  blocker.release();
  commits.wait(last);
  // Every callback ran, once, with success, before its ticket's waiter woke.
  for (uint64_t seq = 2; seq <= 100; ++seq) EXPECT_EQ(told[seq], 1) << "record " << seq;
  EXPECT_EQ(runs, 2);
  const GroupCommit::Stats stats = commits.stats();
  EXPECT_EQ(stats.records, 100u);
  EXPECT_EQ(stats.commits, 2u) << "99 records queued behind one transaction must commit together";
  EXPECT_EQ(store.leases_issued(1), 100u);
}

TEST(GroupCommit, RecordsAreAppliedInAppendOrderAcrossThreads) {
  TempDb db;
  Store store(db.path());
  std::vector<uint64_t> applied;  // (only the writer thread touches it)
  std::mutex order_mu;
  std::vector<uint64_t> tickets_in_order;
  {
    GroupCommit commits(store, {}, {}, /*max_batch=*/7);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
      threads.emplace_back([&] {
        for (int i = 0; i < 50; ++i) {
          // Appended under a lock, as the coordinator does: the ticket order is the decision order.
          std::lock_guard<std::mutex> lock(order_mu);
          const uint64_t n = tickets_in_order.size() + 1;
          tickets_in_order.push_back(n);
          (void)commits.append([&applied, n](Store&) { applied.push_back(n); });
        }
      });
    for (auto& t : threads) t.join();
    commits.flush();
    EXPECT_GE(commits.stats().commits, 200u / 7);
  }
  EXPECT_EQ(applied, tickets_in_order);
}

TEST(GroupCommit, AFailedBatchFailsItsTicketsAndRetriesOnlyRecordsMarkedForRetry) {
  TempDb db;
  Store store(db.path());
  GroupCommit commits(store);
  Blocker blocker;
  bool failed_once = false;
  const uint64_t blocked = blocker.append(commits);
  // The next batch: a phase-like record to keep, a lease, and a write that fails as a full disk does.
  const uint64_t kept = commits.append([](Store& st) { st.set_job_priority(1, 5); st.log_lease(10, 1, 0, 0, 7, 0); },
                                       GroupCommit::Retry::UntilDurable);
  bool dropped_told_durable = true;
  const uint64_t dropped = commits.append(lease_record(11), GroupCommit::Retry::No,
                                          [&dropped_told_durable](bool ok) { dropped_told_durable = ok; });
  const uint64_t failing = commits.append([&failed_once](Store&) {
    if (!failed_once) {
      failed_once = true;
      throw StoreError("disk full (simulated)", /*full=*/true);
    }
  });
  blocker.release();
  commits.wait(blocked);
  for (uint64_t t : {kept, dropped, failing}) EXPECT_THROW(commits.wait(t), StoreError) << "ticket " << t;
  EXPECT_FALSE(dropped_told_durable) << "a record of a failed batch is told so";
  // Nothing of the failed batch is on disk; the kept record commits with the next batch.
  const uint64_t later = commits.append(lease_record(12));
  commits.wait(later);
  EXPECT_EQ(store.leases_issued(1), 2u) << "lease 10 (retried) and 12; lease 11 was dropped";
  EXPECT_EQ(store.last_lease_seq(), 12u);
  EXPECT_EQ(commits.stats().failed_batches, 1u);
}

TEST(GroupCommit, OneClientAtATimeIsCommittedAtOnce) {
  TempDb db;
  Store store(db.path());
  GroupCommit commits(store, {}, std::chrono::milliseconds(300));
  // Each record waited for before the next is appended: nothing to gather, so no interval.
  const auto t0 = std::chrono::steady_clock::now();
  for (uint64_t seq = 1; seq <= 5; ++seq) commits.wait(commits.append(lease_record(seq)));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(250));
  EXPECT_EQ(commits.stats().commits, 5u);
}

TEST(GroupCommit, UnderLoadACommitStartsAtMostOncePerInterval) {
  TempDb db;
  Store store(db.path());
  GroupCommit commits(store, {}, std::chrono::milliseconds(300));
  // Records appended while a batch commits: the next commit waits for the interval since that
  // batch's start, and everything appended until then shares it.
  const auto t0 = std::chrono::steady_clock::now();
  Blocker blocker;
  (void)blocker.append(commits);
  (void)commits.append(lease_record(1));
  blocker.release();
  uint64_t last = 0;
  for (uint64_t seq = 2; seq <= 11; ++seq) last = commits.append(lease_record(seq));
  commits.wait(last);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(290));
  EXPECT_EQ(commits.stats().commits, 2u);
  EXPECT_EQ(store.leases_issued(1), 11u);
}

TEST(GroupCommit, UnderLoadACommitWaitsUpToAnotherIntervalForAsManyRecordsAsTheLast) {
  using namespace std::chrono_literals;
  TempDb db;
  Store store(db.path());
  GroupCommit commits(store, {}, 500ms);
  // A batch of five (appended while the writer was held): the writer is under load.
  Blocker blocker;
  (void)blocker.append(commits);
  uint64_t last = 0;
  for (uint64_t seq = 1; seq <= 5; ++seq) last = commits.append(lease_record(seq));
  blocker.release();
  commits.wait(last);
  const auto batch_start = std::chrono::steady_clock::now();  // (about when that batch started)
  // Four come back at once and the fifth late, after the interval but within two: one commit.
  for (uint64_t seq = 6; seq <= 9; ++seq) last = commits.append(lease_record(seq));
  std::this_thread::sleep_until(batch_start + 700ms);
  const uint64_t late = commits.append(lease_record(10));
  commits.wait(last);
  EXPECT_GE(std::chrono::steady_clock::now() - batch_start, 680ms) << "the first four did not wait for the fifth";
  commits.wait(late);
  EXPECT_EQ(commits.stats().commits, 3u);
  EXPECT_EQ(store.leases_issued(1), 10u);
}

TEST(GroupCommit, WhatWasAppendedIsCommittedWhenTheWriterStops) {
  TempDb db;
  {
    Store store(db.path());
    GroupCommit commits(store);
    for (uint64_t seq = 1; seq <= 20; ++seq) (void)commits.append(lease_record(seq));
  }
  Store reopened(db.path());
  EXPECT_EQ(reopened.leases_issued(1), 20u);
  EXPECT_EQ(reopened.last_lease_seq(), 20u);
}

}  // namespace
}  // namespace tessera::server
