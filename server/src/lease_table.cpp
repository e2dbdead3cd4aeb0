#include "lease_table.h"

namespace tessera::server {

void LeaseTable::add(const LeaseInfo& lease) {
  (void)end(lease.id);
  leases_.emplace(lease.id, lease);
  ++held_[lease.worker];
  by_job_[lease.job].insert(lease.id);
  last_id_ = std::max(last_id_, lease.id);
}

std::optional<LeaseInfo> LeaseTable::end(uint64_t id) {
  auto it = leases_.find(id);
  if (it == leases_.end()) return std::nullopt;
  const LeaseInfo lease = it->second;
  leases_.erase(it);
  if (--held_[lease.worker] == 0) held_.erase(lease.worker);
  auto job = by_job_.find(lease.job);
  job->second.erase(id);
  if (job->second.empty()) by_job_.erase(job);
  return lease;
}

const LeaseInfo* LeaseTable::find(uint64_t id) const {
  auto it = leases_.find(id);
  return it == leases_.end() ? nullptr : &it->second;
}

void LeaseTable::extend(uint64_t id, Clock::time_point expires) {
  if (auto it = leases_.find(id); it != leases_.end()) it->second.expires = expires;
}

std::vector<uint64_t> LeaseTable::of_worker(uint64_t worker) const {
  std::vector<uint64_t> ids;
  if (!holds(worker)) return ids;
  for (const auto& [id, l] : leases_)
    if (l.worker == worker) ids.push_back(id);
  return ids;
}

const std::set<uint64_t>& LeaseTable::job_leases(uint64_t job) const {
  static const std::set<uint64_t> none;
  auto it = by_job_.find(job);
  return it == by_job_.end() ? none : it->second;
}

std::vector<uint64_t> LeaseTable::of_job(uint64_t job) const {
  const std::set<uint64_t>& ids = job_leases(job);
  return {ids.begin(), ids.end()};
}

std::vector<uint64_t> LeaseTable::of_unit(uint64_t job, size_t unit) const {
  std::vector<uint64_t> ids;
  for (uint64_t id : job_leases(job))
    if (leases_.at(id).unit == unit) ids.push_back(id);
  return ids;
}

}  // namespace tessera::server
