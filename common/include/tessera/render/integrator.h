// Integrators: radiance along a camera ray.
//
//   path    unidirectional path tracing with next-event estimation, BSDF sampling and the power
//           heuristic; Russian roulette after rr_depth (Mitsuba 3 style). Depth is counted as
//           Mitsuba does: max_depth = 1 shows only directly visible emitters, 2 adds direct
//           illumination, -1 is unbounded, 0 renders black.
//   direct  Mitsuba's `direct`: at the first hit, emitter_samples light samples and bsdf_samples
//           BSDF samples combined with the power heuristic (sample counts included), plus the
//           radiance of a directly visible emitter.
// li() may return non-finite values on degenerate input; the film drops and counts them.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/rgb.h"
#include "tessera/render/film.h"
#include "tessera/render/sampler.h"
#include "tessera/render/scene.h"

#include <memory>

namespace tessera {

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Radiance arriving at the camera along `ray`. Adds the rays it traces (bounce and shadow rays,
  /// not the camera ray itself) to `counters`.
  virtual Rgb li(const Scene& scene, const Ray& ray, Sampler& sampler, RenderCounters& counters) const = 0;
};

std::unique_ptr<Integrator> make_path_integrator(const IntegratorSettings& settings);
std::unique_ptr<Integrator> make_direct_integrator(const IntegratorSettings& settings);
/// By settings.type.
std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings);

}  // namespace tessera
