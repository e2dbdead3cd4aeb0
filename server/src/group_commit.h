// Group commit: one writer thread applies the coordinator's records (leases, results, phase
// changes) to the store in the order they were appended, many to a transaction, so one fsync makes
// a whole batch durable. Records are appended under the coordinator's lock, where they are decided;
// callers wait for durability after releasing it, and only then answer (a result is acknowledged,
// a lease handed out).
//
// A record may carry a `done` callback, called once its batch is committed (true) or has failed
// (false), before its waiters wake: the coordinator applies a durable result to its job there, or
// ends a lease that could not be logged. The writer runs a batch's callbacks together through the
// `runner` given at construction (the coordinator's: under its lock, taken once per batch).
//
// A batch that fails (a full disk) is rolled back and every ticket in it fails with its error.
// Records appended with Retry::UntilDurable (idempotent full-row writes such as a job's phase) are
// then kept at the head of the queue and committed with the next batch, so the coordinator's
// memory, which has already moved on, reaches the disk once there is room.
#pragma once

#include "tessera/server/store.h"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace tessera::server {

class GroupCommit {
 public:
  using Write = std::function<void(Store&)>;
  using Done = std::function<void(bool durable)>;
  using Runner = std::function<void(const std::function<void()>& callbacks)>;
  enum class Retry { No, UntilDurable };

  /// `min_interval`: under load (the previous batch held more than one request's records, or more
  /// arrived while it committed), a commit starts at least this long after the previous one
  /// started, and records arriving meanwhile join it; it waits up to one more interval for as many
  /// records as the previous batch held. Fewer and larger commits for a latency of at most two
  /// intervals. Otherwise (an idle writer, or one client at a time) a record is committed at once.
  /// `max_batch`: records per transaction at most (bounds a batch's latency and WAL growth).
  explicit GroupCommit(Store& store, Runner runner = {}, std::chrono::microseconds min_interval = {},
                       size_t max_batch = 256);
  /// Commits what is queued, then stops the writer.
  ~GroupCommit();
  GroupCommit(const GroupCommit&) = delete;
  GroupCommit& operator=(const GroupCommit&) = delete;

  /// Queues a write; returns its ticket. Tickets increase in append order.
  [[nodiscard]] uint64_t append(Write write, Retry retry = Retry::No, Done done = {});
  /// Blocks until the batch holding `ticket` is committed; rethrows the error that failed it.
  void wait(uint64_t ticket);
  /// Waits for everything appended so far (rethrows a failure of the last record).
  void flush();

  struct Stats {
    uint64_t commits = 0, records = 0, failed_batches = 0;
  };
  Stats stats() const;

 private:
  struct Record {
    uint64_t ticket;
    Write write;
    Retry retry;
    Done done;
  };
  struct Failure {
    uint64_t first, last;
    std::exception_ptr error;
  };
  void run();
  void fill(std::unique_lock<std::mutex>& lock, std::chrono::steady_clock::time_point last_start);
  void commit(std::vector<Record>& batch);
  void run_callbacks(std::vector<Record>& batch, bool durable);
  bool failed(uint64_t ticket, std::exception_ptr& error) const;

  Store& store_;
  const Runner runner_;
  const std::chrono::microseconds min_interval_;
  const size_t max_batch_;
  mutable std::mutex mu_;
  std::condition_variable queued_cv_;
  // Each waiter sleeps on its own condition variable and is woken only once its ticket is decided
  // (not by every batch that commits before it).
  struct Waiter {
    uint64_t ticket;
    std::condition_variable cv;
  };
  std::vector<Waiter*> waiters_;
  std::deque<Record> queue_;
  std::deque<Failure> failures_;  // the newest few, for waiters that have not looked yet
  uint64_t appended_ = 0, finished_ = 0;
  bool stopping_ = false;
  bool busy_ = false;  // under load: wait for `min_interval` (see the constructor)
  size_t last_batch_ = 0;  // records in the last batch
  size_t wanted_ = SIZE_MAX;  // records the writer is waiting for (see fill())
  Stats stats_;
  std::thread thread_;
};

}  // namespace tessera::server
