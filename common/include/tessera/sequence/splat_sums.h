// A Paths unit's result (pass_program.h): what its light paths added to which pixels of the
// window, in the order they added it. Sparse, since a range of paths reaches the camera at a
// scattering of pixels; the sequencer folds units into a film's splat layer in (pass, unit) order,
// so a pixel's sum is the same bits however the ranges were spread over threads or machines.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/render/bdpt.h"
#include "tessera/render/film.h"

#include <array>
#include <cstdint>
#include <vector>

namespace tessera {

struct SplatSums {
  TileRect window;
  std::vector<uint32_t> pixel;                // row-major index in `window`, per splat
  std::vector<std::array<double, 3>> value;   // per splat
  RenderCounters counters;

  void reset(const TileRect& w) {
    window = w;
    pixel.clear();
    value.clear();
    counters = {};
  }
  /// Adds `v` to pixel `p` (inside the window). A non-finite value adds nothing and is counted.
  void add(Vec2i p, Rgb v) {
    if (!v.is_finite()) {
      ++counters.nonfinite;
      return;
    }
    pixel.push_back(uint32_t(size_t(p.y - window.y0) * size_t(window.width()) + size_t(p.x - window.x0)));
    value.push_back({double(v.r), double(v.g), double(v.b)});
  }
  size_t size() const { return pixel.size(); }
};

/// A light-tracing unit's splats (render/bdpt.h) as its result: one splat per touched pixel, in
/// pixel order (a function of the unit's paths alone).
inline void to_splat_sums(const LightSplats& in, SplatSums& out) {
  out.reset(in.window());
  out.counters = in.counters;
  const std::vector<uint32_t> touched = in.sorted_touched();
  out.pixel.reserve(touched.size());
  out.value.reserve(touched.size());
  for (uint32_t i : touched) {
    const double* s = in.sum(i);
    out.pixel.push_back(i);
    out.value.push_back({s[0], s[1], s[2]});
  }
}

/// A light-tracing unit (PassSpec::same_samples) of a scene's light-tracing integrator: light paths
/// [path_begin, path_end) over the scene's film window, as its result. The one way `tessera
/// render` and a farm worker render such a unit.
inline void render_light_unit(const Scene& scene, uint64_t path_begin, uint64_t path_end, uint32_t seed,
                              SplatSums& out) {
  thread_local LightSplats splats;  // (its window-sized buffers reused from unit to unit)
  splats.reset(film_window(scene.film), scene.film.width, scene.film.height);
  trace_light_paths(scene, path_begin, path_end, seed, splats);
  to_splat_sums(splats, out);
}

}  // namespace tessera
