// fresnel_dielectric against textbook values: normal incidence, Brewster's angle, total internal
// reflection, and the symmetry of the interface seen from both sides.
#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

TEST(Fresnel, NormalIncidence) {
  for (float eta : {1.1f, 1.333f, 1.5f, 2.419f}) {
    const float r0 = (eta - 1.f) * (eta - 1.f) / ((eta + 1.f) * (eta + 1.f));
    float cos_t = 0.f;
    EXPECT_NEAR(fresnel_dielectric(1.f, eta, &cos_t), r0, 1e-6f) << eta;
    EXPECT_NEAR(cos_t, -1.f, 1e-6f);
    // From inside the same interface reflects the same amount at normal incidence.
    EXPECT_NEAR(fresnel_dielectric(-1.f, eta, &cos_t), r0, 1e-6f) << eta;
    EXPECT_NEAR(cos_t, 1.f, 1e-6f);
  }
}

// At Brewster's angle rp = 0, so R is half of rs^2, which is sin^2(ti - tt) / sin^2(ti + tt).
TEST(Fresnel, BrewsterAngleLeavesOnlyRs) {
  for (float eta : {1.333f, 1.5f, 2.0f}) {
    for (bool inside : {false, true}) {
      const double n = inside ? 1.0 / eta : eta;  // relative index seen by the incident light
      const double ti = std::atan(n), tt = std::asin(std::sin(ti) / n);
      const double rs = std::sin(ti - tt) / std::sin(ti + tt);
      float cos_t = 0.f;
      const float c = float(std::cos(ti));
      const float r = fresnel_dielectric(inside ? -c : c, eta, &cos_t);
      EXPECT_NEAR(r, 0.5 * rs * rs, 1e-5) << eta << " inside " << inside;
      EXPECT_NEAR(std::abs(cos_t), std::cos(tt), 1e-5);
      // And it is a minimum of rp: R is below the average of the two polarisations nearby.
      const float r_off = fresnel_dielectric(inside ? -c * 0.9f : c * 0.9f, eta);
      EXPECT_GT(r_off, r);
    }
  }
}

TEST(Fresnel, TotalInternalReflectionAboveCriticalAngle) {
  const float eta = 1.5f;
  const float cos_crit = std::sqrt(1.f - 1.f / (eta * eta));
  float cos_t = 5.f;
  EXPECT_EQ(fresnel_dielectric(-(cos_crit - 1e-3f), eta, &cos_t), 1.f);
  EXPECT_EQ(cos_t, 0.f);
  EXPECT_EQ(fresnel_dielectric(-0.01f, eta), 1.f);
  EXPECT_LT(fresnel_dielectric(-(cos_crit + 1e-2f), eta), 1.f);
  // Never from outside.
  EXPECT_LT(fresnel_dielectric(cos_crit - 1e-3f, eta), 1.f);
}

// Reciprocity of the interface: R(cos_i, eta) == R(cos_t, 1/eta) where cos_t is the refracted cosine,
// and the same from the other side (negative cosines).
TEST(Fresnel, SymmetricInsideOutside) {
  for (float eta : {1.2f, 1.5f, 2.4f}) {
    for (int i = 1; i <= 20; ++i) {
      const float cos_i = i / 20.f;
      float cos_t = 0.f;
      const float r = fresnel_dielectric(cos_i, eta, &cos_t);
      ASSERT_LT(cos_t, 0.f);
      EXPECT_NEAR(fresnel_dielectric(-cos_t, 1.f / eta), r, 2e-5f) << eta << " " << cos_i;
      // Arriving from inside along the reversed refracted ray gives the same R and back cos_i.
      float cos_back = 0.f;
      EXPECT_NEAR(fresnel_dielectric(cos_t, eta, &cos_back), r, 2e-5f);
      EXPECT_NEAR(cos_back, cos_i, 1e-4f);
      // Inside with eta equals outside with 1/eta.
      EXPECT_NEAR(fresnel_dielectric(-cos_i, eta), fresnel_dielectric(cos_i, 1.f / eta), 1e-6f);
    }
  }
  EXPECT_EQ(fresnel_dielectric(0.7f, 1.f), 0.f);
}

TEST(Fresnel, GrazingIncidenceReflectsEverything) {
  EXPECT_NEAR(fresnel_dielectric(1e-6f, 1.5f), 1.f, 1e-4f);
}

// Hemispherical averages: known values for n = 1.5, and (1 - F_int) = (1 - F_ext) / n^2, which is
// what makes plastic with a white base conserve energy exactly.
TEST(Fresnel, DiffuseReflectance) {
  EXPECT_NEAR(fresnel_diffuse_reflectance(1.5f), 0.0918f, 5e-4f);
  EXPECT_NEAR(fresnel_diffuse_reflectance(1.f / 1.5f), 0.5963f, 5e-4f);
  for (float eta : {1.2f, 1.49f, 2.0f}) {
    EXPECT_NEAR(1.f - fresnel_diffuse_reflectance(1.f / eta), (1.f - fresnel_diffuse_reflectance(eta)) / (eta * eta),
                1e-4f);
  }
}

}  // namespace
}  // namespace tessera
