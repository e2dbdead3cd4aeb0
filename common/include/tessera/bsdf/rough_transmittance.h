// Transmittance of a rough dielectric interface, the quantity Mitsuba 0.6 reads from its precomputed
// tables (data/microfacet/*.dat, rtrans.h) for the layered models `roughplastic` and `roughcoating`.
// Those files are not available here, so the same directional albedo is computed at load time.
#pragma once

#include "tessera/bsdf/microfacet.h"

#include <array>
#include <cstddef>
#include <vector>

namespace tessera {

/// Fraction of light arriving at cos_theta_o in (0, 1] that a rough dielectric interface transmits
/// (directional albedo of its transmission lobe, Walter et al. 2007 with Smith G), from a
/// deterministic stratified 64 x 64 estimate. `eta` < 1: arriving from inside.
float rough_dielectric_transmittance(MicrofacetType type, float alpha, float eta, float cos_theta_o);

/// rough_dielectric_transmittance for one (type, alpha, eta), tabulated over cos theta in [0, 1]
/// and linearly interpolated.
class TransmittanceTable {
 public:
  static constexpr int kSize = 64;

  TransmittanceTable(MicrofacetType type, float alpha, float eta);

  float eval(float cos_theta) const;
  /// 2 int_0^1 T(c) c dc (the hemispherical average, e.g. 1 - Fdr for light from inside).
  float cosine_average() const;

 private:
  std::array<float, kSize> t_{};
};

/// Tables at several roughness values for a spatially varying alpha (Mitsuba's 2D slice of its
/// 3D table): eval() interpolates piecewise quadratically in alpha between the nodes, clamping
/// outside them. Tables are built in parallel.
class RoughTransmittance {
 public:
  /// `alphas` ascending; one node gives a table that ignores alpha.
  RoughTransmittance(MicrofacetType type, const std::vector<float>& alphas, float eta);

  float eval(float cos_theta, float alpha) const;

 private:
  /// Lagrange quadratic through nodes first .. first + 2.
  float quadratic(size_t first, float cos_theta, float alpha) const;

  std::vector<float> alphas_;
  std::vector<TransmittanceTable> tables_;
};

}  // namespace tessera
