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
//
// IntegratorSettings::strategy picks how path/volpath estimate direct light (the `direct`
// integrator ignores it). Each is unbiased: for every light path, the weights of the techniques
// that can produce it sum to one. "Light pdf" below is the density with which next-event
// estimation would have sampled the emitter point a BSDF/phase-sampled ray found, from the
// previous vertex (pdf_li or pdf_env times the selection pmf), the density MIS already uses.
//   mis   (default) both techniques, power heuristic. The image is bit-identical to the
//         integrator before strategies existed.
//   bsdf  BSDF/phase sampling only: an emitter hit by a sampled ray counts fully. Next-event
//         estimation is kept for delta lights only (point, spot, directional: no sampled ray can
//         hit them), at full weight; a light sample that picks a non-delta light contributes
//         nothing and traces no shadow ray.
//   nee   next-event estimation at full weight for every light; an emitter hit by a sampled ray
//         counts fully exactly when next-event estimation could not have produced it: the
//         camera ray, a ray after a delta (specular) lobe, or a light pdf of zero (a light the
//         selection never picks, a direction pdf_li does not cover). Otherwise it counts zero.
// The sampler draws the same dimensions under every strategy, so images differ only in weights.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/rgb.h"
#include "tessera/render/aov.h"
#include "tessera/render/film.h"
#include "tessera/render/path_guide.h"
#include "tessera/render/sampler.h"
#include "tessera/render/scene.h"

#include <memory>
#include <string>

namespace tessera {

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Radiance arriving at the camera along `ray`. Adds the rays it traces (bounce and shadow rays,
  /// not the camera ray itself) to `counters`. `guide`: path guiding for this pass (path_guide.h),
  /// or null; integrators that do not guide ignore it. `features`, if given (zeroed by the
  /// caller), receives the sample's AOV features (aov.h; `direct` takes them at the first hit).
  virtual Rgb li(const Scene& scene, const Ray& ray, Sampler& sampler, RenderCounters& counters,
                 const PathGuide* guide, SampleFeatures* features) const = 0;
};

std::unique_ptr<Integrator> make_path_integrator(const IntegratorSettings& settings);
std::unique_ptr<Integrator> make_direct_integrator(const IntegratorSettings& settings);
/// By settings.type.
std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings);

/// "mis", "bsdf", "nee".
const char* sampling_strategy_name(SamplingStrategy strategy);
/// The inverse of sampling_strategy_name; false for an unknown name.
bool parse_sampling_strategy(const std::string& name, SamplingStrategy& out);

}  // namespace tessera
