// Helpers shared by the BSDF tests.
#pragma once

#include "support/chi2.h"
#include "tessera/core/ray.h"
#include "tessera/render/bsdf.h"
#include "tessera/core/vec.h"

#include <cmath>

namespace tessera::test {

/// Unit direction in the local shading frame from polar angle theta and azimuth phi, in degrees.
inline Vec3 direction_deg(float theta_deg, float phi_deg) {
  float t = theta_deg * kPi / 180.f, p = phi_deg * kPi / 180.f;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

/// Chi-square test of `bsdf.sample` against `bsdf.pdf` for the outgoing direction `wo` at `si`.
inline Chi2Result bsdf_chi2_test(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, const Chi2Options& o) {
  return chi2_test(
      Chi2Sampler3([&](Vec2 u, float u1) {
        BsdfSample bs;
        if (!bsdf.sample(si, wo, u1, u, bs)) return Chi2Sample{Vec3(), 0.f, false};
        return Chi2Sample{bs.wi, bs.pdf, true};
      }),
      [&](Vec3 wi) { return double(bsdf.pdf(si, wo, wi)); }, o);
}

}  // namespace tessera::test
