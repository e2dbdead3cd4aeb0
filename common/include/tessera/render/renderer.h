// The render driver: splits the film into tiles and the samples into passes, and renders them in
// parallel such that the result does not depend on how the work was split.
//
// Determinism contract (the render farm relies on it): a pixel's sums are
//   sum over passes, in pass order, of (sum over that pass's sample indices, in index order),
// each sample's value depending only on (scene, pixel, sample index, seed). render_tile() for the
// same (rect, sample range, seed) therefore gives the same bits on any machine, and render() gives
// the same bits for any thread count or tile size.
#pragma once

#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"
#include "tessera/render/path_guide.h"
#include "tessera/render/scene.h"

#include <cstdint>
#include <functional>
#include <vector>

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
  /// Path guiding (path/volpath only): the passes that end within the first half of the samples
  /// train an SD-tree (guiding_trains_pass), each later pass samples with what the previous
  /// training passes learned. The image is the passes after training (or every pass, see
  /// GuidingSettings::discard_training), each sample with weight 1, so it converges to the
  /// unguided image; the learned trees are the same bits for any thread count or tile size.
  bool guiding = false;
  GuidingSettings guiding_settings;
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
};

struct RenderProgress {
  int pass = 0, num_passes = 0;
  int64_t tiles_done = 0, tiles_total = 0;  // over the whole render
  uint32_t samples_done = 0, spp = 0;       // samples per pixel in finished passes
};
/// Called after every finished tile, from worker threads but never concurrently.
using ProgressCallback = std::function<void(const RenderProgress&)>;

/// Sample counts of the passes for `spp` samples, a function of spp alone: 1, 2, 4, ... doubling
/// up to 64 per pass, then 64 per pass; the last pass takes the remainder. Early passes are short
/// so a preview (and the farm's first results) arrive quickly; capped so passes stay balanced.
std::vector<uint32_t> pass_schedule(uint32_t spp);

/// Whether pass `pass` of `passes` (for `spp` samples) trains the guide of a guided render: those
/// that end within the first half of the samples (none with fewer than 2 samples per pixel).
bool guiding_trains_pass(const std::vector<uint32_t>& passes, size_t pass, uint32_t spp);
/// Tiles of `window`, row-major, `tile_size` square (smaller at the right and bottom edges).
std::vector<TileRect> make_tiles(const TileRect& window, int tile_size);

/// Renders samples [sample_begin, sample_end) of every pixel of `rect` into `tile`, which is reset
/// to `rect` first. Uses the scene's camera, filter, sampler type and integrator.
void render_tile(const Scene& scene, const TileRect& rect, uint32_t sample_begin, uint32_t sample_end,
                 uint32_t seed, FilmTile& tile);

/// Renders, for every pixel of `rect`, the samples `samples` gives it (samples.rect contains rect),
/// guided by `guide` when it is given (a farm worker's unit of a guided job), with the AOV sums
/// when `aovs` is set.
void render_tile(const Scene& scene, const TileRect& rect, const PassSamples& samples, uint32_t seed, FilmTile& tile,
                 const PathGuide* guide = nullptr, bool aovs = false);

/// Renders the scene's crop window with settings.spp samples per pixel.
Film render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
            RenderStats* stats = nullptr);

}  // namespace tessera
