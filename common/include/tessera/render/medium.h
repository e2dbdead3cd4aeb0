// Participating media and phase functions.
//
// Frames and units: everything is in WORLD space. A phase function takes `wo`, the unit direction
// from the scattering point back towards where the path came from (minus the ray direction), and
// `wi`, the unit direction towards the next vertex or the light; the scattering angle is the angle
// between -wo and wi, so forward scattering keeps wi close to the ray's direction. eval() is the
// phase function value itself (1/sr; it integrates to 1 over wi, there is no cosine), and pdf() is
// a density with respect to SOLID ANGLE. Media measure distances in world units: a ray's parameter
// t is converted with |ray.d|, so shadow rays with unnormalised directions work.
// Hot path: no method throws or allocates.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"

#include <memory>
#include <string>

namespace tessera {

class PhaseFunction {
 public:
  virtual ~PhaseFunction() = default;
  virtual float eval(Vec3 wo, Vec3 wi) const = 0;
  virtual float pdf(Vec3 wo, Vec3 wi) const { return eval(wo, wi); }
  /// Samples wi; returns the weight eval/pdf (1 for the phase functions here) or 0 on failure.
  virtual float sample(Vec3 wo, Vec2 u, Vec3& wi, float& pdf) const = 0;
};

/// Isotropic: 1 / (4 pi) everywhere.
std::unique_ptr<PhaseFunction> make_isotropic_phase();
/// Henyey-Greenstein with mean cosine g in (-1, 1); g > 0 scatters forward.
std::unique_ptr<PhaseFunction> make_hg_phase(float g);

struct MediumSample {
  float t = kInfinity;     // ray parameter of the scattering point (valid when `scattered`)
  bool scattered = false;  // false: the ray reached tmax (the next surface, or infinity)
  /// Throughput factor for the segment: transmittance times sigma_s over the sampling density at a
  /// scattering point, transmittance over the probability of getting through otherwise.
  Rgb weight;
};

class Medium {
 public:
  virtual ~Medium() = default;
  /// Samples the next interaction along `ray` before parameter `tmax` (kInfinity: none), with two
  /// uniform numbers (`u.x` picks the colour channel that drives the distance, `u.y` the distance).
  virtual void sample(const Ray& ray, float tmax, Vec2 u, MediumSample& out) const = 0;
  /// Transmittance between ray.o and ray.at(tmax).
  virtual Rgb transmittance(const Ray& ray, float tmax) const = 0;
  /// True when nothing scatters (sigma_s = 0): paths only lose energy passing through.
  virtual bool absorbing_only() const = 0;
  const PhaseFunction& phase() const { return *phase_; }

 protected:
  explicit Medium(std::shared_ptr<const PhaseFunction> phase) : phase_(std::move(phase)) {}

 private:
  std::shared_ptr<const PhaseFunction> phase_;
};

/// Homogeneous medium with extinction `sigma_t` and single-scattering albedo `albedo` (both per
/// channel, per world unit for sigma_t).
std::unique_ptr<Medium> make_homogeneous_medium(Rgb sigma_t, Rgb albedo, std::shared_ptr<const PhaseFunction> phase);

}  // namespace tessera
