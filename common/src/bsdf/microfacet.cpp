#include "tessera/bsdf/microfacet.h"

#include "tessera/core/check.h"
#include "tessera/core/ray.h"

#include <algorithm>
#include <cmath>

namespace tessera {

std::optional<MicrofacetType> parse_microfacet_type(std::string_view name) {
  if (name == "beckmann") return MicrofacetType::Beckmann;
  if (name == "ggx") return MicrofacetType::Ggx;
  if (name == "phong") return MicrofacetType::Phong;
  return std::nullopt;
}

MicrofacetDistribution::MicrofacetDistribution(MicrofacetType type, float alpha_u, float alpha_v)
    : type_(type), alpha_u_(std::max(alpha_u, 1e-4f)), alpha_v_(std::max(alpha_v, 1e-4f)) {
  if (type_ == MicrofacetType::Phong) {
    // Mitsuba 0.6: the Phong exponent whose lobe matches a Beckmann lobe of roughness alpha.
    exponent_u_ = std::max(2.f / (alpha_u_ * alpha_u_) - 2.f, 0.f);
    exponent_v_ = std::max(2.f / (alpha_v_ * alpha_v_) - 2.f, 0.f);
  }
}

float MicrofacetDistribution::phong_exponent(Vec3 m) const {
  float sin2 = 1.f - m.z * m.z;
  if (is_isotropic() || sin2 <= 1e-12f) return exponent_u_;
  float inv = 1.f / sin2;
  return exponent_u_ * (m.x * m.x * inv) + exponent_v_ * (m.y * m.y * inv);
}

float MicrofacetDistribution::project_roughness(Vec3 v) const {
  float sin2 = 1.f - v.z * v.z;
  if (is_isotropic() || sin2 <= 0.f) return alpha_u_;
  float inv = 1.f / sin2;
  float cos_phi2 = v.x * v.x * inv, sin_phi2 = v.y * v.y * inv;
  return std::sqrt(cos_phi2 * alpha_u_ * alpha_u_ + sin_phi2 * alpha_v_ * alpha_v_);
}

float MicrofacetDistribution::D(Vec3 m) const {
  float c = m.z;
  if (c <= 0.f) return 0.f;
  float c2 = c * c;
  float result;
  if (type_ == MicrofacetType::Phong) {
    float e = phong_exponent(m);
    result = std::sqrt((exponent_u_ + 2.f) * (exponent_v_ + 2.f)) * (0.5f * kInvPi) * std::pow(c, e);
  } else {
    // tan^2(theta) scaled per axis: (x^2 / au^2 + y^2 / av^2) / cos^2.
    float t = (m.x * m.x / (alpha_u_ * alpha_u_) + m.y * m.y / (alpha_v_ * alpha_v_)) / c2;
    if (type_ == MicrofacetType::Beckmann) {
      result = std::exp(-t) / (kPi * alpha_u_ * alpha_v_ * c2 * c2);
    } else {
      float root = 1.f + t;
      result = 1.f / (kPi * alpha_u_ * alpha_v_ * c2 * c2 * root * root);
    }
  }
  // Mitsuba drops values that cannot matter, avoiding denormals and inf * 0 downstream.
  if (!(result * c >= 1e-20f) || !std::isfinite(result)) return 0.f;
  return result;
}

float MicrofacetDistribution::G1(Vec3 v, Vec3 m) const {
  if (dot(v, m) * v.z <= 0.f) return 0.f;
  float sin_theta = std::sqrt(std::max(0.f, 1.f - v.z * v.z));
  float tan_theta = std::abs(sin_theta / v.z);
  if (tan_theta == 0.f) return 1.f;
  float alpha = project_roughness(v);
  if (type_ == MicrofacetType::Ggx) {
    float root = alpha * tan_theta;
    return 2.f / (1.f + std::sqrt(1.f + root * root));
  }
  // Beckmann, and Phong through its Beckmann equivalent: Walter et al.'s rational approximation.
  float a = 1.f / (alpha * tan_theta);
  if (a >= 1.6f) return 1.f;
  float a2 = a * a;
  return (3.535f * a + 2.181f * a2) / (1.f + 2.276f * a + 2.577f * a2);
}

float MicrofacetDistribution::pdf_m(Vec3 wi, Vec3 m) const {
  if (m.z <= 0.f) return 0.f;
  if (samples_visible_normals()) {
    if (wi.z <= 0.f) return 0.f;
    return G1(wi, m) * std::max(0.f, dot(wi, m)) * D(m) / wi.z;
  }
  return D(m) * m.z;
}

namespace {

// Azimuth of an anisotropic lobe: phi = atan(k tan(2 pi u)) on the branch of 2 pi u, whose density
// k / (2 pi (k^2 cos^2 phi + sin^2 phi)) is the azimuthal marginal of D cos for all three types.
float anisotropic_phi(float k, float u) {
  return std::atan(k * std::tan(kPi + 2.f * kPi * u)) + kPi * std::floor(2.f * u + 0.5f);
}

}  // namespace

bool MicrofacetDistribution::sample_m(Vec3 wi, Vec2 u, MicrofacetSample& out) const {
  out.pdf = 0.f;
  Vec3 m;
  if (type_ == MicrofacetType::Ggx) {
    if (wi.z <= 0.f) return false;
    // Heitz 2018: stretch to the hemisphere configuration, sample the projected half disk, unstretch.
    Vec3 vh = normalize(Vec3(alpha_u_ * wi.x, alpha_v_ * wi.y, wi.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    Vec3 t1 = lensq > 0.f ? Vec3(-vh.y, vh.x, 0.f) / std::sqrt(lensq) : Vec3(1.f, 0.f, 0.f);
    Vec3 t2 = cross(vh, t1);
    float r = std::sqrt(u.x), phi = 2.f * kPi * u.y;
    float p1 = r * std::cos(phi), p2 = r * std::sin(phi);
    float s = 0.5f * (1.f + vh.z);
    p2 = (1.f - s) * std::sqrt(std::max(0.f, 1.f - p1 * p1)) + s * p2;
    Vec3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.f, 1.f - p1 * p1 - p2 * p2));
    m = Vec3(alpha_u_ * nh.x, alpha_v_ * nh.y, std::max(0.f, nh.z));
    float len = length(m);
    if (!(len > 0.f)) return false;
    m = m / len;
  } else {
    float phi, cos_theta;
    if (type_ == MicrofacetType::Beckmann) {
      float alpha2;
      if (is_isotropic()) {
        phi = 2.f * kPi * u.y;
        alpha2 = alpha_u_ * alpha_u_;
      } else {
        phi = anisotropic_phi(alpha_v_ / alpha_u_, u.y);
        float c = std::cos(phi), sn = std::sin(phi);
        alpha2 = 1.f / (c * c / (alpha_u_ * alpha_u_) + sn * sn / (alpha_v_ * alpha_v_));
      }
      float tan2 = -alpha2 * std::log1p(-u.x);
      cos_theta = 1.f / std::sqrt(1.f + tan2);
    } else {
      float e;
      if (is_isotropic()) {
        phi = 2.f * kPi * u.y;
        e = exponent_u_;
      } else {
        phi = anisotropic_phi(std::sqrt((exponent_u_ + 2.f) / (exponent_v_ + 2.f)), u.y);
        float c = std::cos(phi), sn = std::sin(phi);
        e = exponent_u_ * c * c + exponent_v_ * sn * sn;
      }
      cos_theta = std::pow(1.f - u.x, 1.f / (e + 2.f));
    }
    float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    m = Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
  }
  // The reported density is pdf_m itself, so that sample and pdf agree to the last bit.
  out.pdf = pdf_m(wi, m);
  if (!(out.pdf > 0.f) || !std::isfinite(out.pdf)) {
    out.pdf = 0.f;
    return false;
  }
  out.m = m;
  return true;
}

}  // namespace tessera
