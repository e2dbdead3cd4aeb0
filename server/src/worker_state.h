// A worker's state as the coordinator sees it. Only Coordinator::Impl::set_worker_state changes it
// (and logs the change); everything else reads it.
//
//   Idle <-> Busy          it holds leases or not
//   Idle/Busy -> Lost      silent for kMissedHeartbeats heartbeat intervals: its leases are re-issued
//   Lost -> Idle/Busy      heard from again (its results are still taken)
//   any -> Draining        an operator drains it: it finishes what it renders and gets no more
//   any -> Gone            it signed off (final)
#pragma once

namespace tessera::server {

enum class WorkerState { Idle, Busy, Draining, Lost, Gone };

const char* worker_state_name(WorkerState s);
inline constexpr WorkerState kWorkerStates[] = {WorkerState::Idle, WorkerState::Busy, WorkerState::Draining,
                                                WorkerState::Lost, WorkerState::Gone};
/// Idle or Busy: a worker that takes new work.
inline bool is_live(WorkerState s) { return s == WorkerState::Idle || s == WorkerState::Busy; }

/// Heartbeat intervals a worker may miss before it is declared dead and its leases re-issued.
inline constexpr int kMissedHeartbeats = 3;

}  // namespace tessera::server
