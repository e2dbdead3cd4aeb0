#include "retention_plan.h"

#include <algorithm>
#include <set>

namespace tessera::server {

namespace {

// A bundle as the plan sees it: its jobs' references and its last use including their ends.
struct BundleUse {
  uint64_t bytes = 0;
  double last_use = 0;
  int refs = 0;       // jobs not (yet) planned for deletion that use it
};

class Planner {
 public:
  Planner(const std::vector<RetentionJob>& jobs, const std::map<std::string, RetentionBundle>& bundles) {
    for (const auto& [hash, b] : bundles) {
      use_[hash] = {b.bytes, b.last_use, 0};
      plan_.total += b.bytes;
    }
    for (const RetentionJob& j : jobs) {
      plan_.total += j.bytes;
      if (j.finished) finished_.push_back(&j);
      auto b = use_.find(j.scene);
      if (b == use_.end()) continue;
      ++b->second.refs;
      if (j.finished) b->second.last_use = std::max(b->second.last_use, j.ended);
    }
    std::sort(finished_.begin(), finished_.end(), [](const RetentionJob* a, const RetentionJob* b) {
      return a->ended != b->ended ? a->ended < b->ended : a->id < b->id;
    });
    plan_.remaining = plan_.total;
  }

  void age_limit(double max_age, double now) {
    for (const RetentionJob* j : finished_)
      if (now - j->ended > max_age) drop_job(*j);
    for (auto& [hash, b] : use_)
      if (b.refs == 0 && now - b.last_use > max_age) drop_bundle(hash);
  }

  void size_limit(uint64_t max_bytes, double grace, double now) {
    size_t next = 0;
    while (plan_.remaining > max_bytes) {
      while (next < finished_.size() && dropped_jobs_.count(finished_[next]->id)) ++next;
      const RetentionJob* job = next < finished_.size() ? finished_[next] : nullptr;
      const std::string* bundle = oldest_unused_bundle(grace, now);
      if (bundle && (!job || use_[*bundle].last_use <= job->ended)) drop_bundle(*bundle);
      else if (job) drop_job(*job);
      else break;  // only queued, running or recent work is left
    }
  }

  RetentionPlan take() { return std::move(plan_); }

 private:
  const std::string* oldest_unused_bundle(double grace, double now) const {
    const std::string* oldest = nullptr;
    for (const auto& [hash, b] : use_)
      if (!dropped_bundles_.count(hash) && b.refs == 0 && now - b.last_use > grace &&
          (!oldest || b.last_use < use_.at(*oldest).last_use))
        oldest = &hash;
    return oldest;
  }
  void drop_job(const RetentionJob& j) {
    if (!dropped_jobs_.insert(j.id).second) return;
    plan_.jobs.push_back(j.id);
    plan_.remaining -= j.bytes;
    if (auto b = use_.find(j.scene); b != use_.end()) --b->second.refs;
  }
  void drop_bundle(const std::string& hash) {
    if (!dropped_bundles_.insert(hash).second) return;
    plan_.bundles.push_back(hash);
    plan_.remaining -= use_[hash].bytes;
  }

  std::map<std::string, BundleUse> use_;
  std::vector<const RetentionJob*> finished_;  // oldest first
  std::set<uint64_t> dropped_jobs_;
  std::set<std::string> dropped_bundles_;
  RetentionPlan plan_;
};

}  // namespace

RetentionPlan plan_retention(const std::vector<RetentionJob>& jobs, const std::map<std::string, RetentionBundle>& bundles,
                             const RetentionLimits& limits, double now) {
  Planner planner(jobs, bundles);
  if (limits.max_age > 0) planner.age_limit(limits.max_age, now);
  if (limits.max_bytes > 0) planner.size_limit(limits.max_bytes, limits.bundle_grace, now);
  return planner.take();
}

}  // namespace tessera::server
