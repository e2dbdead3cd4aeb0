// Rendering one Tile unit: every pixel sample of a rectangle, with the scene's camera, filter,
// sampler and integrator.
//
// Determinism (the render farm relies on it): each sample's value depends only on (scene, pixel,
// sample index, seed), and a tile's sums add its pixels' samples in index order, so render_tile()
// for the same (rect, samples, seed) gives the same bits on any machine. The pass sequencer
// (sequence/pass_sequencer.h) adds tiles to the film in an order that makes the image independent
// of the tiling, the thread count and the farm.
#pragma once

#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"
#include "tessera/render/integrator.h"
#include "tessera/render/path_guide.h"
#include "tessera/render/scene.h"

#include <cstdint>

namespace tessera {

class Sampler;

/// Renders samples [sample_begin, sample_end) of every pixel of `rect` into `tile`, which is reset
/// to `rect` first.
/// The scene's time for the pixel sample the sampler is at (motion blur: uniform over the shutter
/// from Sampler::kTimeDimension; without a shutter interval, shutter_open). Light subpaths use
/// the camera ray's time.
float camera_sample_time(const Scene& scene, Sampler& sampler);

void render_tile(const Scene& scene, const TileRect& rect, uint32_t sample_begin, uint32_t sample_end,
                 uint32_t seed, FilmTile& tile);

/// Renders, for every pixel of `rect`, the samples `samples` gives it (samples.rect contains rect),
/// guided by `guide` when it is given, with the AOV sums when `aovs` is set.
void render_tile(const Scene& scene, const TileRect& rect, const PassSamples& samples, uint32_t seed, FilmTile& tile,
                 const PathGuide* guide = nullptr, bool aovs = false);

/// The same with an integrator made once for many tiles (make_integrator(scene.integrator)).
void render_tile(const Scene& scene, const Integrator& integrator, const TileRect& rect, const PassSamples& samples,
                 uint32_t seed, FilmTile& tile, const PathGuide* guide, bool aovs);

}  // namespace tessera
