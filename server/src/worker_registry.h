// The workers the coordinator knows: their registration rows, when each was last heard from, its
// state (worker_state.h) and what it has done. set_state() is the one place a state changes.
// Workers registered with an earlier process keep their ids: one is adopted (its row read from the
// store off the lock) the first time it is heard from again. Not thread-safe: the coordinator
// guards it with its mutex.
#pragma once

#include "lease_table.h"
#include "worker_state.h"
#include "tessera/farm/protocol.h"
#include "tessera/server/store.h"

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace tessera::server {

struct WorkerInfo {
  WorkerRow row;
  Clock::time_point last_seen;
  WorkerState state = WorkerState::Idle;
  uint64_t units_done = 0, samples_done = 0;
  double render_seconds = 0;
  WorkerMemory memory;  // as its last heartbeat reported it
};

class WorkerRegistry {
 public:
  /// Ids up to `registered_before` belong to an earlier process.
  explicit WorkerRegistry(uint64_t registered_before = 0) : before_(registered_before) {}
  void registered_before(uint64_t last_id) { before_ = last_id; }

  WorkerInfo* find(uint64_t id);
  /// A worker registered now.
  WorkerInfo& add(const WorkerRow& row);
  /// Whether `id` is an earlier process's worker not adopted yet (its row is to be read).
  bool needs_adoption(uint64_t id) const { return id > 0 && id <= before_ && !workers_.contains(id); }
  /// Adopts an earlier process's worker (false if another request did first).
  bool adopt(const WorkerRow& row);
  /// It was heard from now.
  void saw(WorkerInfo& w) { w.last_seen = Clock::now(); }

  struct Change {
    WorkerState from, to;
  };
  /// The one place a worker's state changes; nothing for one that signed off (final) or is in
  /// `to` already.
  std::optional<Change> set_state(WorkerInfo& w, WorkerState to);

  /// Workers that take work (Idle or Busy).
  size_t live() const;
  std::map<std::string, int> count_by_state() const;
  const std::map<uint64_t, WorkerInfo>& all() const { return workers_; }

 private:
  std::map<uint64_t, WorkerInfo> workers_;
  uint64_t before_;
};

}  // namespace tessera::server
