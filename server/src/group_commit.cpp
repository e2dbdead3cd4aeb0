#include "group_commit.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <utility>

namespace tessera::server {

namespace {
// Failed batches remembered for their waiters; a waiter looks within microseconds of the failure,
// so a short history is plenty.
constexpr size_t kFailureHistory = 64;
// A batch of retried records that failed again (the disk is still full) is tried again this often
// when nothing new arrives.
constexpr auto kRetryPause = std::chrono::milliseconds(500);
// The most records one request appends (a result and the next lease sent with its answer).
constexpr size_t kOneRequest = 2;
}  // namespace

GroupCommit::GroupCommit(Store& store, Runner runner, std::chrono::microseconds min_interval, size_t max_batch)
    : store_(store),
      runner_(std::move(runner)),
      min_interval_(min_interval),
      max_batch_(std::max<size_t>(1, max_batch)),
      thread_([this] { run(); }) {}

GroupCommit::~GroupCommit() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  queued_cv_.notify_all();
  thread_.join();
}

uint64_t GroupCommit::append(Write write, Retry retry, Done done) {
  std::lock_guard<std::mutex> lock(mu_);
  const uint64_t ticket = ++appended_;
  queue_.push_back({ticket, std::move(write), retry, std::move(done)});
  // The writer waits for a first record, a full batch, as many as it wants (see fill()), or
  // (retried records queued) anything new; not woken for each record in between.
  if (queue_.size() == 1 || queue_.size() >= std::min(wanted_, max_batch_) || queue_.front().ticket <= finished_)
    queued_cv_.notify_one();
  return ticket;
}

bool GroupCommit::failed(uint64_t ticket, std::exception_ptr& error) const {
  for (const Failure& f : failures_)
    if (ticket >= f.first && ticket <= f.last) {
      error = f.error;
      return true;
    }
  return false;
}

void GroupCommit::wait(uint64_t ticket) {
  std::unique_lock<std::mutex> lock(mu_);
  if (finished_ < ticket) {
    Waiter me{ticket, {}};
    waiters_.push_back(&me);
    me.cv.wait(lock, [&] { return finished_ >= ticket; });
    std::erase(waiters_, &me);
  }
  std::exception_ptr error;
  if (failed(ticket, error)) std::rethrow_exception(error);
}

void GroupCommit::flush() {
  uint64_t last;
  {
    std::lock_guard<std::mutex> lock(mu_);
    last = appended_;
  }
  wait(last);
}

GroupCommit::Stats GroupCommit::stats() const {
  std::lock_guard<std::mutex> lock(mu_);
  return stats_;
}

void GroupCommit::run() {
  std::vector<Record> batch;
  std::unique_lock<std::mutex> lock(mu_);
  auto last_start = std::chrono::steady_clock::now() - min_interval_;
  for (;;) {
    queued_cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    // Stopping: what is queued is committed first; records only waiting for a retry are given up.
    if (queue_.empty() || (stopping_ && queue_.back().ticket <= finished_)) return;
    if (busy_) fill(lock, last_start);
    last_start = std::chrono::steady_clock::now();
    while (!queue_.empty() && batch.size() < max_batch_) {
      batch.push_back(std::move(queue_.front()));
      queue_.pop_front();
    }
    lock.unlock();
    commit(batch);  // the records' own work and the fsync, with appends going on meanwhile
    lock.lock();
    // Busy: more than one request's records (a result and the lease sent with its answer) in the
    // batch, or more decided while it committed.
    busy_ = batch.size() > kOneRequest || !queue_.empty();
    last_batch_ = batch.size();
    batch.clear();
    for (Waiter* w : waiters_)  // (under the lock: a waiter leaves, and its cv goes, only after it)
      if (w->ticket <= finished_) w->cv.notify_one();
    // Only records kept for a retry are queued: pause unless something new arrives.
    if (!queue_.empty() && queue_.back().ticket <= finished_)
      queued_cv_.wait_for(lock, kRetryPause, [&] { return stopping_ || queue_.back().ticket > finished_; });
  }
}

void GroupCommit::fill(std::unique_lock<std::mutex>& lock, std::chrono::steady_clock::time_point last_start) {
  // The batch fills until the interval since the last commit's start is over; then, for up to one
  // more interval, until it holds as many records as the last batch: the clients that batch
  // answered are mostly on their way back, and one commit for all of them is one fsync, not two.
  queued_cv_.wait_until(lock, last_start + min_interval_, [&] { return stopping_ || queue_.size() >= max_batch_; });
  wanted_ = std::min(last_batch_, max_batch_);
  queued_cv_.wait_until(lock, last_start + 2 * min_interval_, [&] { return stopping_ || queue_.size() >= wanted_; });
  wanted_ = SIZE_MAX;
}

void GroupCommit::commit(std::vector<Record>& batch) {
  std::exception_ptr error;
  bool retry = false;  // worth trying the retried records again later
  try {
    store_.transaction([&] {
      for (Record& r : batch) r.write(store_);
    });
  } catch (const std::exception& e) {
    spdlog::error("state database: a batch of {} record(s) was not committed: {}", batch.size(), e.what());
    error = std::current_exception();
    const auto* store_error = dynamic_cast<const StoreError*>(&e);
    retry = store_error && store_error->disk_full;
  }
  run_callbacks(batch, !error);
  std::lock_guard<std::mutex> lock(mu_);
  ++(error ? stats_.failed_batches : stats_.commits);
  if (!error) stats_.records += batch.size();
  // The tickets this batch decides: those not already answered by an earlier (failed) batch.
  const uint64_t first = finished_ + 1, last = std::max(finished_, batch.back().ticket);
  if (error && first <= last) {
    failures_.push_back({first, last, error});
    if (failures_.size() > kFailureHistory) failures_.pop_front();
  }
  if (retry)  // kept, in their order, ahead of everything appended since (see the header)
    for (auto r = batch.rbegin(); r != batch.rend(); ++r)
      if (r->retry == Retry::UntilDurable) queue_.push_front(std::move(*r));
  finished_ = last;
}

void GroupCommit::run_callbacks(std::vector<Record>& batch, bool durable) {
  const auto callbacks = [&] {
    for (Record& r : batch)
      if (r.done) std::exchange(r.done, nullptr)(durable);  // (once: a retried record is not told again)
  };
  try {
    if (runner_) runner_(callbacks);
    else callbacks();
  } catch (const std::exception& e) {  // (a callback must not stop the writer)
    spdlog::error("state database: after a commit: {}", e.what());
  }
}

}  // namespace tessera::server
