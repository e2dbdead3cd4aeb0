#include "worker_registry.h"

namespace tessera::server {

WorkerInfo* WorkerRegistry::find(uint64_t id) {
  auto it = workers_.find(id);
  return it == workers_.end() ? nullptr : &it->second;
}

WorkerInfo& WorkerRegistry::add(const WorkerRow& row) {
  WorkerInfo& w = workers_[row.id];
  w.row = row;
  w.last_seen = Clock::now();
  return w;
}

bool WorkerRegistry::adopt(const WorkerRow& row) {
  if (workers_.contains(row.id)) return false;
  add(row);
  return true;
}

std::optional<WorkerRegistry::Change> WorkerRegistry::set_state(WorkerInfo& w, WorkerState to) {
  if (w.state == to || w.state == WorkerState::Gone) return std::nullopt;
  const Change change{w.state, to};
  w.state = to;
  return change;
}

size_t WorkerRegistry::live() const {
  size_t n = 0;
  for (const auto& [id, w] : workers_) n += is_live(w.state);
  return n;
}

std::map<std::string, int> WorkerRegistry::count_by_state() const {
  std::map<std::string, int> counts;
  for (WorkerState s : kWorkerStates) counts[worker_state_name(s)] = 0;
  for (const auto& [id, w] : workers_) ++counts[worker_state_name(w.state)];
  return counts;
}

}  // namespace tessera::server
