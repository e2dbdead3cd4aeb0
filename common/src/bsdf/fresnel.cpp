#include "tessera/bsdf/fresnel.h"

#include <algorithm>
#include <cmath>

namespace tessera {

float fresnel_dielectric(float cos_theta_i, float eta, float* cos_theta_t) {
  if (eta == 1.f) {
    if (cos_theta_t) *cos_theta_t = -cos_theta_i;
    return 0.f;
  }
  // Arriving from inside: swap the media.
  float scale = cos_theta_i > 0.f ? 1.f / eta : eta;
  float cos_t_sqr = 1.f - (1.f - cos_theta_i * cos_theta_i) * (scale * scale);
  if (cos_t_sqr <= 0.f) {
    if (cos_theta_t) *cos_theta_t = 0.f;
    return 1.f;
  }
  float cos_i = std::abs(cos_theta_i);
  float cos_t = std::sqrt(cos_t_sqr);
  float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  if (cos_theta_i < 0.f) {
    // Seen from inside the relative index is 1/eta; the formulas above are written for outside.
    rs = (cos_i - cos_t / eta) / (cos_i + cos_t / eta);
    rp = (cos_i / eta - cos_t) / (cos_i / eta + cos_t);
  }
  if (cos_theta_t) *cos_theta_t = cos_theta_i > 0.f ? -cos_t : cos_t;
  return std::clamp(0.5f * (rs * rs + rp * rp), 0.f, 1.f);
}

namespace {

// Exact unpolarised reflectance of a conductor (Mitsuba's fresnelConductorExact), in double: in
// float, (eta^2 - k^2)^2 overflows to NaN once eta or k passes ~4e9, and near grazing incidence
// sin^2 = 1 - cos^2 rounds to 1, which made an index-matched interface (eta 1, k 0) a mirror
// (F = 1 instead of 0 at cos 1e-4). Double keeps both exact enough for any float input below 1e38.
float conductor_channel(float cos_i_f, float eta_f, float k_f) {
  const double cos_i = cos_i_f, eta = eta_f, k = k_f;
  const double cos2 = cos_i * cos_i, sin2 = 1.0 - cos2, sin4 = sin2 * sin2;
  const double temp1 = eta * eta - k * k - sin2;
  const double a2pb2 = std::sqrt(std::max(temp1 * temp1 + 4.0 * k * k * eta * eta, 0.0));
  const double a = std::sqrt(std::max(0.5 * (a2pb2 + temp1), 0.0));
  const double term1 = a2pb2 + cos2, term2 = 2.0 * a * cos_i;
  const double rs2 = (term1 - term2) / (term1 + term2);
  const double term3 = a2pb2 * cos2 + sin4, term4 = term2 * sin2;
  const double rp2 = rs2 * (term3 - term4) / (term3 + term4);
  const double f = 0.5 * (rp2 + rs2);
  return std::isnan(f) ? 1.f : float(std::clamp(f, 0.0, 1.0));  // NaN only for infinite eta or k: a mirror
}

}  // namespace

Rgb fresnel_conductor(float cos_theta_i, Rgb eta, Rgb k) {
  float c = std::clamp(cos_theta_i, 0.f, 1.f);
  return {conductor_channel(c, eta.r, k.r), conductor_channel(c, eta.g, k.g), conductor_channel(c, eta.b, k.b)};
}

}  // namespace tessera
