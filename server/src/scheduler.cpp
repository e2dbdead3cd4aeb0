#include "scheduler.h"

#include <limits>

namespace tessera::server {

namespace {

std::optional<UnitChoice> fresh_choice(std::span<const JobCandidate> jobs, int* priority) {
  const JobCandidate* best = nullptr;
  for (const JobCandidate& j : jobs) {
    if (j.excluded || !j.fresh_unit) continue;
    if (!best || j.priority > best->priority) best = &j;  // (equal: the earlier job stays)
  }
  if (!best) return std::nullopt;
  *priority = best->priority;
  return UnitChoice{best->job, *best->fresh_unit, false};
}

}  // namespace

int speculation_floor(std::span<const JobCandidate> jobs) {
  int priority = std::numeric_limits<int>::min();
  (void)fresh_choice(jobs, &priority);
  return priority;
}

std::optional<UnitChoice> choose_unit(std::span<const JobCandidate> jobs, std::span<const LeaseCandidate> leases,
                                      uint64_t worker, bool speculate) {
  int floor = std::numeric_limits<int>::min();
  std::optional<UnitChoice> fresh = fresh_choice(jobs, &floor);
  if (!speculate) return fresh;
  const LeaseCandidate* best = nullptr;
  for (const LeaseCandidate& l : leases) {
    if (l.excluded || l.finished || !l.overdue || l.worker == worker || l.copies != 1) continue;
    if (fresh && l.priority <= floor) continue;
    if (!best || l.priority > best->priority) best = &l;  // (equal: the older lease stays)
  }
  if (!best) return fresh;
  return UnitChoice{best->job, best->unit, true};
}

}  // namespace tessera::server
