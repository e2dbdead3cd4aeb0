#include "worker_state.h"

namespace tessera::server {

const char* worker_state_name(WorkerState s) {
  switch (s) {
    case WorkerState::Idle: return "idle";
    case WorkerState::Busy: return "busy";
    case WorkerState::Draining: return "draining";
    case WorkerState::Lost: return "lost";
    case WorkerState::Gone: return "gone";
  }
  return "unknown";
}

}  // namespace tessera::server
