#include "tessera/sequence/local_driver.h"

#include "tessera/core/check.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <mutex>
#include <vector>

namespace tessera {

namespace {

// Locally an artifact is stored as soon as it is made: the passes that use it open at once.
void store_artifacts(PassSequencer& sequencer) {
  while (auto made = sequencer.take_artifact()) sequencer.artifact_stored(made->iteration, "");
}

}  // namespace

void run_locally(PassSequencer& sequencer, UnitRenderer& renderer, int threads, const UnitProgress& progress) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  std::mutex mutex;  // guards the sequencer while units run; taken once per unit
  arena.execute([&] {
    for (store_artifacts(sequencer); !sequencer.complete(); store_artifacts(sequencer)) {
      const uint32_t pass = uint32_t(sequencer.complete_passes());
      TESSERA_CHECK(pass < sequencer.open_passes());  // (a complete pass opens the next, or stops)
      renderer.prepare(sequencer, pass);
      // Pass by pass: the film holds exactly the passes before a barrier when it is reached.
      std::vector<UnitWork> work;
      for (uint32_t i = 0; i < sequencer.units_in(pass); ++i)
        if (sequencer.ready(sequencer.unit(pass, i))) work.push_back(sequencer.work(sequencer.unit(pass, i)));
      tbb::parallel_for(tbb::blocked_range<size_t>(0, work.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
        UnitResult result;
        for (size_t k = r.begin(); k != r.end(); ++k) {
          renderer.render(sequencer, work[k], result);
          std::lock_guard<std::mutex> lock(mutex);
          TESSERA_CHECK(sequencer.add_result(sequencer.unit(pass, work[k].index), std::move(result)));
          if (progress) progress(sequencer, pass);
        }
      });
    }
  });
}

}  // namespace tessera
