// Bidirectional path tracing (`bdpt`, Veach 1997 ch. 10) and light tracing (`ptracer`).
//
// A pixel sample has a camera subpath (from the sampler's usual dimensions, sampler.h) and a light
// subpath (from Sampler::kLightDimension), both a function of (pixel, sample index, seed) only.
// A path of s light vertices and t camera vertices is the strategy (s, t):
//   s = 0      the camera subpath hits an emitter (or escapes to an environment)
//   s = 1      next-event estimation at a camera vertex (the light picked as `path` picks it)
//   s >= 2     a light vertex connected to a camera vertex
//   t = 1      a light vertex connected to the camera (light tracing), splatted onto the film
// (s = 1, t = 1, an emitter point connected straight to the camera, is left out: s = 0 renders
// directly visible emitters.) The strategies are combined with the power heuristic; the weights
// use the recursive partial quantities of Georgiev, "Implementing Vertex Connection and Merging"
// (2012), with vertex merging's terms zero. Densities are converted between solid angle and area
// with geometric normals throughout; Russian roulette stays out of the weights (it is unbiased
// on its own). Light subpaths start at a light chosen by power (LightSampler::sample_emitter).
//
// Units: a Tile unit runs every strategy with t >= 2 through Integrator::li (the pixel's own
// samples); the light-tracing strategies (t = 1) run in a Paths unit of the same samples
// (PassSpec::same_samples), which retraces the same light subpaths and splats what reaches the
// camera through the pixel filter (LightSplats). `ptracer` is the same with only t = 1 and, in
// its Tile units, s = 0 for emitters the camera sees directly.
//
// Light vertices carry importance: BSDFs are evaluated with their arguments swapped (adjoint
// BSDF, so refraction's radiance scaling is undone) and Veach's shading-normal correction
// |wo.ns||wi.ng| / (|wo.ng||wi.ns|) (bdpt_adjoint.h). Surfaces only: a scene with media renders
// with volpath (the loader decides).
#pragma once

#include "tessera/render/film.h"
#include "tessera/render/integrator.h"
#include "tessera/render/sampler.h"
#include "tessera/render/scene.h"

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace tessera {

/// True for integrators whose renders have light-tracing units (Paths passes).
bool traces_light_paths(const IntegratorSettings& settings);

/// What a range of light paths added to the film's window: dense sums over the window and the
/// pixels touched, in the order they were first touched (so converting to a sparse list is
/// deterministic).
class LightSplats {
 public:
  /// `full_width/height`: the whole film; the splats are scaled so that the film's image is its
  /// mean plus splat sum / (light paths per window pixel), see film.h.
  void reset(const TileRect& window, int full_width, int full_height);
  /// Adds `value` landing at raster point `raster` through the filter (null: a box over the pixel).
  void add(Vec2 raster, Rgb value, const Filter* filter);
  const TileRect& window() const { return window_; }
  /// Touched pixels (row-major index in the window), each once, sorted.
  std::vector<uint32_t> sorted_touched() const;
  const double* sum(uint32_t pixel) const { return &sums_[size_t(pixel) * 3]; }
  RenderCounters counters;

 private:
  void add_pixel(int x, int y, double r, double g, double b);
  TileRect window_;
  double scale_ = 1;
  std::vector<double> sums_;
  std::vector<uint32_t> touched_;
  std::vector<uint8_t> is_touched_;
};

/// Light paths [path_begin, path_end) of a pass whose first path is sample `sample_begin` (path k:
/// sample sample_begin + (k - first) / window pixels of window pixel (k - first) mod window pixels,
/// first = sample_begin * window pixels), each connected to the camera (t = 1) with its MIS
/// weight (bdpt) or alone (ptracer), into `out` (reset by the caller).
void trace_light_paths(const Scene& scene, uint64_t path_begin, uint64_t path_end, uint32_t seed, LightSplats& out);

/// The strategies (s, t) bdpt has for paths of 1 .. max_length segments, by length then s.
std::vector<std::pair<int, int>> bdpt_strategies(int max_length);

std::unique_ptr<Integrator> make_bdpt_integrator(const IntegratorSettings& settings);
/// Its li() renders only what the camera sees directly (s = 0 at the first hit).
std::unique_ptr<Integrator> make_ptracer_integrator(const IntegratorSettings& settings);

}  // namespace tessera
