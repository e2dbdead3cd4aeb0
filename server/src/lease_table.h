// The leases in flight: which worker renders which unit of which job, until when. The table owns
// its invariants: a lease enters in add() and leaves in end() only, a worker's count of held
// leases is its entries here, a job's leases are indexed (oldest first), and ids are never reused,
// also across restarts (they continue after the highest one an earlier process logged).
// Not thread-safe: the coordinator guards it with its mutex.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <vector>

namespace tessera::server {

using Clock = std::chrono::steady_clock;

struct LeaseInfo {
  uint64_t id = 0, job = 0, worker = 0;
  size_t unit = 0;
  Clock::time_point expires;
  Clock::time_point issued;  // (for a lease re-adopted after a restart: when it was re-adopted)
};

class LeaseTable {
 public:
  /// Ids continue after `last_id`.
  explicit LeaseTable(uint64_t last_id = 0) : last_id_(last_id) {}
  uint64_t next_id() { return ++last_id_; }
  void continue_after(uint64_t last_id) { last_id_ = std::max(last_id_, last_id); }

  /// The one place a lease enters (replacing one of the same id).
  void add(const LeaseInfo& lease);
  /// The one place a lease leaves: the lease that ended, if it was in flight.
  std::optional<LeaseInfo> end(uint64_t id);
  const LeaseInfo* find(uint64_t id) const;
  /// The lease is alive until `expires` (its worker reported it).
  void extend(uint64_t id, Clock::time_point expires);

  size_t size() const { return leases_.size(); }
  /// Whether the worker holds any lease.
  bool holds(uint64_t worker) const { return held_.contains(worker); }
  /// Ids of the worker's leases / the job's (oldest first) / the job's unit's.
  std::vector<uint64_t> of_worker(uint64_t worker) const;
  std::vector<uint64_t> of_job(uint64_t job) const;
  std::vector<uint64_t> of_unit(uint64_t job, size_t unit) const;
  /// The job's leases, oldest first (empty if none).
  const std::set<uint64_t>& job_leases(uint64_t job) const;
  /// Every lease, oldest first.
  const std::map<uint64_t, LeaseInfo>& all() const { return leases_; }

 private:
  std::map<uint64_t, LeaseInfo> leases_;
  std::unordered_map<uint64_t, uint32_t> held_;         // by worker: its entries in leases_
  std::unordered_map<uint64_t, std::set<uint64_t>> by_job_;  // lease ids
  uint64_t last_id_;
};

}  // namespace tessera::server
