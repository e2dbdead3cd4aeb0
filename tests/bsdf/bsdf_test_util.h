// Helpers shared by the BSDF tests.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

#include <cmath>

namespace tessera::test {

/// Unit direction in the local shading frame from polar angle theta and azimuth phi, in degrees.
inline Vec3 direction_deg(float theta_deg, float phi_deg) {
  float t = theta_deg * kPi / 180.f, p = phi_deg * kPi / 180.f;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

}  // namespace tessera::test
