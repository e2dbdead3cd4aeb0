// Rough-interface transmittance tables shared by roughplastic and roughcoating (see the header).
// Each entry is a stratified estimate over the distribution's own micro-normal sampler, so it is
// deterministic and its noise is far below the tables' interpolation error.
#include "tessera/bsdf/rough_transmittance.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace tessera {

float rough_dielectric_transmittance(MicrofacetType type, float alpha, float eta, float cos_theta_o) {
  constexpr int kGrid = 64;
  const MicrofacetDistribution distr(type, alpha);
  const float c = std::clamp(cos_theta_o, 1e-4f, 1.f);
  const Vec3 wo(std::sqrt(std::max(0.f, 1.f - c * c)), 0.f, c);
  double sum = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      MicrofacetSample ms;
      if (!distr.sample_m(wo, Vec2((i + 0.5f) / kGrid, (j + 0.5f) / kGrid), ms) || !(ms.pdf > 0.f)) continue;
      const float wo_m = dot(wo, ms.m);
      if (wo_m <= 0.f) continue;
      float cos_t = 0.f;
      const float f = fresnel_dielectric(wo_m, eta, &cos_t);
      if (f >= 1.f) continue;  // total internal reflection
      // Refraction about m (cos_t < 0: the far side of the micro-facet).
      const Vec3 wt = (-1.f / eta) * wo + (wo_m / eta + cos_t) * ms.m;
      if (cos_theta(wt) >= 0.f) continue;
      // Walter et al.'s estimator of the transmitted fraction: (1 - F) D G |wo.m| / (cos_o pdf_m).
      sum += double((1.f - f) * distr.D(ms.m) * distr.G(wo, wt, ms.m) * wo_m / (c * ms.pdf));
    }
  }
  return float(std::min(1.0, sum / (kGrid * kGrid)));
}

TransmittanceTable::TransmittanceTable(MicrofacetType type, float alpha, float eta) {
  for (int k = 0; k < kSize; ++k) t_[k] = rough_dielectric_transmittance(type, alpha, eta, float(k) / (kSize - 1));
}

float TransmittanceTable::eval(float c) const {
  const float x = std::clamp(c, 0.f, 1.f) * (kSize - 1);
  const int k = std::min(int(x), kSize - 2);
  const float f = x - float(k);
  return (1.f - f) * t_[k] + f * t_[k + 1];
}

float TransmittanceTable::cosine_average() const {
  // int_0^1 T(sqrt(x)) dx, midpoint rule in x.
  constexpr int kSteps = 4096;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) sum += eval(std::sqrt((i + 0.5f) / kSteps));
  return float(sum / kSteps);
}

RoughTransmittance::RoughTransmittance(MicrofacetType type, const std::vector<float>& alphas, float eta)
    : alphas_(alphas) {
  TESSERA_CHECK(!alphas_.empty() && std::is_sorted(alphas_.begin(), alphas_.end()));
  // Tables are independent, so building them in parallel gives the same bits as in sequence.
  std::vector<std::optional<TransmittanceTable>> tables(alphas_.size());
  tbb::parallel_for(size_t(0), alphas_.size(), [&](size_t k) { tables[k].emplace(type, alphas_[k], eta); });
  tables_.reserve(alphas_.size());
  for (auto& t : tables) tables_.push_back(*t);
}

float RoughTransmittance::quadratic(size_t first, float cos_theta, float alpha) const {
  const float a0 = alphas_[first], a1 = alphas_[first + 1], a2 = alphas_[first + 2];
  const float w0 = (alpha - a1) * (alpha - a2) / ((a0 - a1) * (a0 - a2));
  const float w1 = (alpha - a0) * (alpha - a2) / ((a1 - a0) * (a1 - a2));
  const float w2 = (alpha - a0) * (alpha - a1) / ((a2 - a0) * (a2 - a1));
  return w0 * tables_[first].eval(cos_theta) + w1 * tables_[first + 1].eval(cos_theta) +
         w2 * tables_[first + 2].eval(cos_theta);
}

float RoughTransmittance::eval(float cos_theta, float alpha) const {
  const size_t n = alphas_.size();
  if (n == 1 || !(alpha > alphas_.front())) return tables_.front().eval(cos_theta);
  if (alpha >= alphas_.back()) return tables_.back().eval(cos_theta);
  const size_t k = size_t(std::upper_bound(alphas_.begin(), alphas_.end(), alpha) - alphas_.begin()) - 1;
  const float f = (alpha - alphas_[k]) / (alphas_[k + 1] - alphas_[k]);
  if (n == 2) return (1.f - f) * tables_[0].eval(cos_theta) + f * tables_[1].eval(cos_theta);
  // Blend of the two quadratics through the neighbouring nodes (a Catmull-Rom-like scheme on an
  // uneven grid): continuous in alpha and far closer than linear interpolation for the same nodes.
  const size_t left = k >= 1 ? k - 1 : 0, right = k + 2 < n ? k : n - 3;
  const float t = std::clamp((1.f - f) * quadratic(left, cos_theta, alpha) + f * quadratic(right, cos_theta, alpha),
                             0.f, 1.f);
  return t;
}

}  // namespace tessera
