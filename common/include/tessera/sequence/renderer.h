// `tessera render`: the path tracer's program (pass_program.h) run on this machine by the pass
// sequencer, the same one a farm job runs on its coordinator.
//
// Determinism contract (the render farm relies on it): a pixel's sums are
//   sum over passes, in pass order, of (sum over that pass's sample indices, in index order),
// each sample's value depending only on (scene, pixel, sample index, seed) (render/render_tile.h).
// render() therefore gives the same bits for any thread count or tile size, and a farm job with
// the same settings gives render()'s bits.
#pragma once

#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"
#include "tessera/render/render_tile.h"
#include "tessera/render/scene.h"
#include "tessera/sequence/pass_schedule.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace tessera {

struct RenderSettings {
  int spp = 4;            // samples per pixel
  uint32_t seed = 0;
  int threads = 0;        // 0: every hardware thread
  int tile_size = 32;     // pixels per tile side
  /// > 0: stop after the first pass at which the estimated relMSE (noise_estimate.h) of the film
  /// is at most this; spp is then the budget. Decided on whole passes only, so the image equals
  /// a render with the spp reached (and a farm job with the same target).
  double target_error = 0;
  /// Path guiding (path/volpath only; guide_plan() in path_program.h decides, unset: as the
  /// scene's integrator says): iterations of 1, 2, 4, ... samples per pixel (guide_iterations),
  /// each sampling with what the ones before learned; the image is the last iteration, or the
  /// last few combined by inverse variance (GuidingSettings::combination), so it converges to the
  /// unguided image; the learned trees are the same bits for any thread count or tile size.
  std::optional<bool> guiding;
  /// Guiding's settings; unset: the scene's guided_path integrator's, else the defaults.
  std::optional<GuidingSettings> guiding_settings;
  /// Adaptive sampling (adaptive.h): later passes spend their samples where the film's variance
  /// estimate says the error is. spp stays the total; a pixel's samples keep consecutive indices.
  bool adaptive = false;
  AdaptiveSettings adaptive_settings;
  /// Keep the AOV sums (aov.h) in the film; the beauty image is the same bits either way.
  bool aovs = false;
};

struct RenderStats {
  RenderCounters counters;  // samples, camera/bounce/shadow rays, NaN/Inf samples dropped
  double seconds = 0;
  uint32_t spp_done = 0;      // samples per pixel rendered (less than spp when a target stopped it)
  double noise_estimate = 0;  // estimated relMSE of the result (only computed with a target)
  size_t guide_leaves = 0, guide_bytes = 0;  // the learned SD-tree, when guided
  float guide_gain = 0.f;                     // its predicted gain (guide_gain.h; 0: not decided)
  bool guide_stepped_aside = false;           // guiding stepped aside: the rest rendered unguided
};

struct RenderProgress {
  int pass = 0, num_passes = 0;
  int64_t tiles_done = 0, tiles_total = 0;  // over the whole render
  uint32_t samples_done = 0, spp = 0;       // samples per pixel in finished passes
  /// Of all the render's work: its units' samples done over those planned (light paths count as
  /// samples), so a progress bar moves as the work does whatever the passes are.
  double done_fraction = 0;
};
/// Called after every finished tile, from worker threads but never concurrently.
using ProgressCallback = std::function<void(const RenderProgress&)>;

/// Why a render of `type` cannot have these settings (empty when it can): only the path tracer has
/// a per-pixel noise estimate (target error, adaptive sampling), guides and AOVs. `tessera render`
/// and a farm job's plan both ask here.
std::string technique_settings_error(IntegratorType type, bool aovs, double target_error, bool adaptive, bool guiding);

/// Renders the scene's crop window with settings.spp samples per pixel.
Film render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
            RenderStats* stats = nullptr);

}  // namespace tessera
