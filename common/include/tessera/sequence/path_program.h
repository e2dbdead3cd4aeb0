// The path tracer's passes: pass_schedule(spp) as Tile passes into one film, with the barriers
// that a target error, adaptive sampling and path guiding add. `tessera render`, `tessera submit`
// and the coordinator build a render's sequencer here, so they cannot disagree about it.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/adaptive.h"
#include "tessera/render/scene.h"
#include "tessera/sequence/pass_program.h"
#include "tessera/sequence/pass_sequencer.h"

#include <optional>
#include <string>

namespace tessera {

/// A guided render's start: the SD-tree's bounds (the scene's) and guiding's settings.
struct GuidePlan {
  Bounds3 bounds;
  GuidingSettings settings;
};

/// Whether and how a render of `scene` is guided: as asked (`requested`), else as its integrator
/// says (a guided_path integrator is); only path and volpath over a scene with bounds are. The
/// settings are `settings`, else the scene's guided_path integrator's, else the defaults. The one
/// place this is decided.
std::optional<GuidePlan> guide_plan(const Scene& scene, std::optional<bool> requested,
                                    const std::optional<GuidingSettings>& settings = std::nullopt);

/// What the path tracer asks of its passes: the settings `tessera render` and a farm job share.
struct PathProgramOptions {
  uint32_t spp = 0;
  double target_error = 0;
  bool adaptive = false;
  AdaptiveSettings adaptive_settings;
  std::optional<GuidePlan> guide;
  /// Light tracing (render/bdpt.h traces_light_paths): each Tile pass is followed by a Paths pass
  /// of the same samples (PassSpec::same_samples) that splats its light subpaths onto the film.
  bool light_paths = false;
};

/// Why `options` cannot be run, or empty: light tracing has no per-pixel noise estimate for a
/// target error or adaptive sampling, and no guide.
std::string path_program_error(const PathProgramOptions& options);

/// The program: with a target error every pass after the first may stop the render. Adaptive: the
/// passes that adaptive_pass() allows, and all after them, are barriers with adaptive counts.
/// Guided: the passes are guide_iterations()' iterations, each cut by iteration_passes(); iteration
/// k renders with the guide learned over iterations 0 .. k-1 (artifact k; the first pass of
/// iteration k > 0 is a barrier) and, but for the last, feeds artifact k + 1. The last iteration
/// enters film 0 (GuideCombination::Discard), or the last `combined_iterations` enter a film each,
/// combined by inverse variance; the others enter none. With a single iteration (fewer than 3
/// samples a pixel) nothing is guided. Throws std::invalid_argument with path_program_error()'s
/// reason.
PassProgram path_program(const PathProgramOptions& options);

/// The sequencer of that program over `frame`, with the guide's training (guide_training.h) as its
/// artifact builder when a pass is guided.
PassSequencer path_sequencer(const PathProgramOptions& options, const SequenceFrame& frame);
/// The sequencer of a program kept as planned (a farm job's), its artifacts `guide`'s training.
/// Throws std::invalid_argument when its passes render with artifacts and there is no guide.
PassSequencer path_sequencer(PassProgram program, const SequenceFrame& frame, const std::optional<GuidePlan>& guide);

}  // namespace tessera
