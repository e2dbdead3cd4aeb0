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

// Exact unpolarised reflectance of a conductor (Mitsuba's fresnelConductorExact).
float conductor_channel(float cos_i, float eta, float k) {
  float cos2 = cos_i * cos_i, sin2 = 1.f - cos2, sin4 = sin2 * sin2;
  float temp1 = eta * eta - k * k - sin2;
  float a2pb2 = std::sqrt(std::max(temp1 * temp1 + 4.f * k * k * eta * eta, 0.f));
  float a = std::sqrt(std::max(0.5f * (a2pb2 + temp1), 0.f));
  float term1 = a2pb2 + cos2, term2 = 2.f * a * cos_i;
  float rs2 = (term1 - term2) / (term1 + term2);
  float term3 = a2pb2 * cos2 + sin4, term4 = term2 * sin2;
  float rp2 = rs2 * (term3 - term4) / (term3 + term4);
  return std::clamp(0.5f * (rp2 + rs2), 0.f, 1.f);
}

}  // namespace

Rgb fresnel_conductor(float cos_theta_i, Rgb eta, Rgb k) {
  float c = std::clamp(cos_theta_i, 0.f, 1.f);
  return {conductor_channel(c, eta.r, k.r), conductor_channel(c, eta.g, k.g), conductor_channel(c, eta.b, k.b)};
}

}  // namespace tessera
