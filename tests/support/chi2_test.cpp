// Self-tests of the chi-square harness: its statistics are right, it accepts correct samplers and
// it rejects wrong ones (so the sampling tests built on it can fail).
#include "support/chi2.h"

#include "tessera/core/sampling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera::test {
namespace {

// Q(k, x) for integer k has the closed form e^-x sum_{i<k} x^i / i!.
double gamma_q_integer(int k, double x) {
  double term = std::exp(-x), sum = 0;
  for (int i = 0; i < k; ++i) {
    sum += term;
    term *= x / (i + 1);
  }
  return sum;
}

TEST(Chi2Stats, IncompleteGammaMatchesClosedForms) {
  for (int k : {1, 2, 5, 10, 50}) {
    for (double x : {0.1, 1.0, 3.0, 10.0, 40.0, 80.0}) {
      double q = regularized_gamma_q(k, x);
      EXPECT_NEAR(q, gamma_q_integer(k, x), 1e-12 + 1e-9 * gamma_q_integer(k, x)) << "k=" << k << " x=" << x;
      EXPECT_NEAR(regularized_gamma_p(k, x) + q, 1.0, 1e-12);
    }
  }
  // P(1/2, x) = erf(sqrt(x)).
  for (double x : {0.01, 0.5, 2.0, 7.0}) EXPECT_NEAR(regularized_gamma_p(0.5, x), std::erf(std::sqrt(x)), 1e-12);
}

TEST(Chi2Stats, PValuesAtKnownQuantiles) {
  // Upper 5% / 1% points of chi-square distributions (standard tables).
  EXPECT_NEAR(chi2_p_value(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(chi2_p_value(23.209251, 10), 0.01, 1e-6);
  EXPECT_NEAR(chi2_p_value(135.806723, 100), 0.01, 1e-6);
  // Large dof (a ~ 2500): the mean of chi^2(k) is k and its median ~ k - 2/3.
  EXPECT_NEAR(chi2_p_value(4999.0 - 2.0 / 3.0, 4999), 0.5, 1e-3);
  EXPECT_LT(chi2_p_value(6000, 4999), 1e-20);
}

Chi2Options quick_options(const std::string& name) {
  Chi2Options o;
  o.name = name;
  o.sample_count = 400000;
  o.cos_theta_bins = 20;
  o.phi_bins = 40;
  return o;
}

TEST(Chi2Harness, AcceptsUniformSphere) {
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_uniform_sphere(u), kInv4Pi}; },
                     [](Vec3) { return double(kInv4Pi); }, quick_options("uniform sphere"));
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-6);
  EXPECT_EQ(r.valid_samples, 400000u);
}

TEST(Chi2Harness, AcceptsCosineHemisphereWithDefaultResolution) {
  auto r = chi2_test(
      [](Vec2 u) {
        Vec3 w = square_to_cosine_hemisphere(u);
        return Chi2Sample{w, cosine_hemisphere_pdf(w.z)};
      },
      [](Vec3 w) { return double(cosine_hemisphere_pdf(w.z)); }, Chi2Options{});
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

TEST(Chi2Harness, AcceptsLobeMixtureUsingTheThirdNumber) {
  // 30% cosine lobe about -z, 70% about +z.
  auto pdf = [](Vec3 w) { return 0.7 * cosine_hemisphere_pdf(w.z) + 0.3 * cosine_hemisphere_pdf(-w.z); };
  auto r = chi2_test(
      [&](Vec2 u, float lobe) {
        Vec3 w = square_to_cosine_hemisphere(u);
        if (lobe < 0.3f) w.z = -w.z;
        return Chi2Sample{w, float(pdf(w))};
      },
      pdf, quick_options("lobe mixture"));
  EXPECT_TRUE(r.passed) << r.message;
}

TEST(Chi2Harness, RejectsCosineSamplesAgainstUniformHemisphere) {
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_cosine_hemisphere(u), 0.f}; },
                     [](Vec3 w) { return w.z > 0.f ? 1.0 / (2.0 * kChi2Pi) : 0.0; },
                     quick_options("cosine vs uniform"));
  EXPECT_FALSE(r.passed);
  EXPECT_LT(r.p_value, 1e-10);
  EXPECT_NE(r.message.find("rejects"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("worst bins"), std::string::npos) << r.message;
}

TEST(Chi2Harness, DetectsASmallBias) {
  // Samples uniform, pdf claims 3% more density in the upper hemisphere than in the lower one.
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_uniform_sphere(u), 0.f}; },
                     [](Vec3 w) { return (w.z > 0.f ? 1.03 : 0.97) * kInv4Pi; }, Chi2Options{});
  EXPECT_FALSE(r.passed) << r.message;
}

TEST(Chi2Harness, RejectsSamplesWherePdfIsZero) {
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_uniform_sphere(u), 0.f}; },
                     [](Vec3 w) { return w.z > 0.f ? 1.0 / (2.0 * kChi2Pi) : 0.0; },
                     quick_options("sphere vs hemisphere"));
  EXPECT_FALSE(r.passed);
  EXPECT_NE(r.message.find("integrates to 0"), std::string::npos) << r.message;
}

TEST(Chi2Harness, RejectsPdfIntegratingAboveOne) {
  // Samples and pdf shapes agree, but the pdf is twice too large.
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_uniform_sphere(u), 0.f}; },
                     [](Vec3) { return 2.0 * kInv4Pi; }, quick_options("double pdf"));
  EXPECT_FALSE(r.passed);
  EXPECT_NEAR(r.pdf_integral, 2.0, 1e-6);
  EXPECT_NE(r.message.find("integrates to 2"), std::string::npos) << r.message;
}

TEST(Chi2Harness, RejectsMisreportedSamplePdf) {
  auto r = chi2_test(
      [](Vec2 u) {
        Vec3 w = square_to_cosine_hemisphere(u);
        return Chi2Sample{w, 1.1f * cosine_hemisphere_pdf(w.z)};
      },
      [](Vec3 w) { return double(cosine_hemisphere_pdf(w.z)); }, quick_options("misreported pdf"));
  EXPECT_FALSE(r.passed);
  EXPECT_NE(r.message.find("report a pdf"), std::string::npos) << r.message;
}

TEST(Chi2Harness, RejectsNonUnitDirections) {
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_uniform_sphere(u) * 2.f, 0.f}; },
                     [](Vec3) { return double(kInv4Pi); }, quick_options("non-unit"));
  EXPECT_FALSE(r.passed);
  EXPECT_NE(r.message.find("unit vectors"), std::string::npos) << r.message;
}

TEST(Chi2Harness, InvalidSamplesAreNotCounted) {
  // Uniform sphere with the lower half rejected: the valid samples still follow the (sub-normalised)
  // upper-hemisphere part of the density, as for a BSDF whose sampling sometimes fails.
  auto r = chi2_test(
      [](Vec2 u) {
        Vec3 w = square_to_uniform_sphere(u);
        return Chi2Sample{w, 0.f, w.z > 0.f};
      },
      [](Vec3 w) { return w.z > 0.f ? double(kInv4Pi) : 0.0; }, quick_options("half rejected"));
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(r.pdf_integral, 0.5, 1e-6);
}

TEST(Chi2Harness, SidakCorrectionTightensAlpha) {
  Chi2Options o = quick_options("sidak");
  o.test_count = 10;
  auto r = chi2_test([](Vec2 u) { return Chi2Sample{square_to_uniform_sphere(u), 0.f}; },
                     [](Vec3) { return double(kInv4Pi); }, o);
  EXPECT_NEAR(r.alpha, 1.0 - std::pow(0.99, 0.1), 1e-12);
  EXPECT_TRUE(r.passed) << r.message;
}

}  // namespace
}  // namespace tessera::test
