// Running a pass sequencer (pass_sequencer.h) on this machine: the units of the first incomplete
// pass in parallel, then the next, storing each artifact at once. `tessera render` runs the path
// tracer this way; any technique's units run the same way, and a farm job runs the same sequencer
// on its coordinator, so the two give the same bits.
#pragma once

#include "tessera/sequence/pass_sequencer.h"

#include <functional>

namespace tessera {

/// What renders a technique's units.
class UnitRenderer {
 public:
  virtual ~UnitRenderer() = default;
  /// Before the units of `pass` are rendered, with none in flight (e.g. a recorder for training).
  virtual void prepare(PassSequencer& sequencer, uint32_t pass) {}
  /// Renders one unit into `result` (its fields reset by the renderer). Called from many threads
  /// at once; `sequencer` is not changed meanwhile.
  virtual void render(const PassSequencer& sequencer, const UnitWork& work, UnitResult& result) = 0;
};

/// Called after each unit's result is in, never concurrently.
using UnitProgress = std::function<void(const PassSequencer&, uint32_t pass)>;

/// Renders every planned unit of `sequencer` with up to `threads` threads (0: every core).
void run_locally(PassSequencer& sequencer, UnitRenderer& renderer, int threads, const UnitProgress& progress = {});

}  // namespace tessera
