// The sun/sky models of Mitsuba 0.5/0.6 against ../shared/data/sunsky: solar position (SPEC §3),
// Hosek-Wilkie sky radiance (check_sky_rgb.txt), the sun's RGB radiance (check_sun_rgb.txt).
#include "tessera/light/sunsky/hosek_sky.h"
#include "tessera/light/sunsky/solar_position.h"
#include "tessera/light/sunsky/sun_spectrum.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace tessera {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// Rows of numbers of a check file ('#' lines skipped).
std::vector<std::vector<double>> read_rows(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::vector<double> row;
    for (double v; s >> v;) row.push_back(v);
    if (!row.empty()) rows.push_back(row);
  }
  return rows;
}

double rel_err(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-30); }

TEST(SolarPosition, MatchesTheWorkedValuesOfTheSpec) {
  SunTimeAndPlace tokyo;  // Mitsuba's defaults: 2010-07-10 15:00 in Tokyo
  SunAngles a = solar_position(tokyo);
  EXPECT_NEAR(a.theta / kDeg, 43.921, 1e-3);
  EXPECT_NEAR(a.phi / kDeg, 265.752, 1e-3);
  Vec3 d = sunsky_direction(a.theta, a.phi);
  EXPECT_NEAR(d.x, -0.6918, 1e-4);
  EXPECT_NEAR(d.y, 0.7203, 1e-4);
  EXPECT_NEAR(d.z, 0.0514, 1e-4);

  tokyo.hour = 12;
  SunAngles noon = solar_position(tokyo);
  EXPECT_NEAR(noon.theta / kDeg, 13.749, 1e-3);
  EXPECT_NEAR(noon.phi / kDeg, 193.212, 1e-3);
}

TEST(SolarPosition, DirectionAndAnglesRoundTrip) {
  for (double theta : {0.1, 0.7, 1.5})
    for (double phi : {0.2, 2.0, 4.0, 6.0}) {
      SunAngles back = sun_angles_from_direction(sunsky_direction(theta, phi) * 3.f);
      EXPECT_NEAR(back.theta, theta, 1e-6);
      EXPECT_NEAR(back.phi, phi, 1e-6);
    }
  // Landmarks of the frame: east (phi = 90 deg) is +x, north (phi = 0) is -z.
  Vec3 east = sunsky_direction(90 * kDeg, 90 * kDeg), north = sunsky_direction(90 * kDeg, 0);
  EXPECT_NEAR(east.x, 1.f, 1e-6f);
  EXPECT_NEAR(north.z, -1.f, 1e-6f);
}

TEST(HosekSky, MatchesTheCheckValues) {
  const std::string path = test::shared_path("data/sunsky/check_sky_rgb.txt");
  TESSERA_REQUIRE_FILE(path);
  auto rows = read_rows(path);
  ASSERT_EQ(rows.size(), 54u);
  double worst = 0;
  for (const auto& r : rows) {
    ASSERT_EQ(r.size(), 11u);
    HosekSky sky(r[0], Rgb(float(r[1]), float(r[2]), float(r[3])), r[4] * kDeg);
    Rgb by_gamma = sky.eval(r[5] * kDeg, r[7] * kDeg);
    const double sun_phi = 1.234;
    Rgb by_direction = sky.eval_direction(r[5] * kDeg, sun_phi + r[6] * kDeg, sun_phi, 1.0);
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, rel_err(by_gamma[c], r[8 + c]));
      EXPECT_NEAR(by_gamma[c], r[8 + c], 1e-5 * r[8 + c] + 1e-12) << "row T=" << r[0] << " sun " << r[4]
                                                                  << " view " << r[5] << "/" << r[6] << " ch " << c;
      EXPECT_NEAR(by_direction[c], r[8 + c], 2e-5 * r[8 + c] + 1e-12);
    }
  }
  std::printf("[ sky ] worst relative error against check_sky_rgb.txt: %.2e\n", worst);
}

TEST(HosekSky, ZeroBelowTheHorizonAndStretchWidensTheSky) {
  HosekSky sky(3.0, Rgb(0.2f), 40 * kDeg);
  EXPECT_EQ(sky.eval(95 * kDeg, 50 * kDeg), Rgb(0.f));
  EXPECT_GT(sky.eval_above(90 * kDeg, 50 * kDeg).g, 0.f);
  // With stretch 2 the view at 120 deg from the zenith sees what 60 deg sees without it.
  Rgb stretched = sky.eval_direction(120 * kDeg, 1.0, 0.3, 2.0);
  Rgb plain = sky.eval_direction(60 * kDeg, 1.0, 0.3, 1.0);
  EXPECT_EQ(stretched, plain);
}

TEST(SunSpectrum, MatchesTheCheckValuesInBothInterpolationVariants) {
  const std::string path = test::shared_path("data/sunsky/check_sun_rgb.txt");
  TESSERA_REQUIRE_FILE(path);
  auto rows = read_rows(path);
  ASSERT_EQ(rows.size(), 80u);
  double worst = 0, worst_xyz = 0, worst_bug = 0;
  for (const auto& r : rows) {
    ASSERT_EQ(r.size(), 11u);
    SunRadiance s = sun_radiance(r[0], r[1] * kDeg);
    SunRadiance b = sun_radiance(r[0], r[1] * kDeg, SunInterpolation::Mitsuba06Swapped);
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, rel_err(s.rgb[c], r[2 + c]));
      worst_xyz = std::max(worst_xyz, rel_err(s.xyz[c], r[5 + c]));
      worst_bug = std::max(worst_bug, rel_err(b.rgb[c], r[8 + c]));
      EXPECT_NEAR(s.rgb[c], r[2 + c], 2e-5 * r[2 + c]) << "T=" << r[0] << " zenith " << r[1] << " ch " << c;
      EXPECT_NEAR(s.xyz[c], r[5 + c], 2e-5 * r[5 + c]) << "T=" << r[0] << " zenith " << r[1] << " ch " << c;
      // The swapped interpolant jumps at every table node, so quadratures differ there: ours is
      // exact per open interval, the check file's 0.02 nm trapezoids take node values. 5e-4 covers it
      // (the two variants differ by up to 3.8e-2, so the test still tells them apart).
      EXPECT_NEAR(b.rgb[c], r[8 + c], 5e-4 * r[8 + c]) << "swapped: T=" << r[0] << " zenith " << r[1] << " ch " << c;
    }
  }
  std::printf("[ sun ] worst relative error: RGB %.2e, XYZ %.2e, 0.6-release variant %.2e\n", worst, worst_xyz,
              worst_bug);
}

TEST(SunSpectrum, DiskSolidAngleAndSpecExample) {
  // 0.2679 deg; SPEC §6 prints 4.6766e-3 rad, a slip for 4.6757e-3 (its solid angle is right).
  EXPECT_NEAR(kSunHalfAngle, 0.2679 * kDeg, 1e-9);
  EXPECT_NEAR(sun_solid_angle(), 6.8683e-5, 1e-9);
  Rgb zenith = sun_radiance(3.0, 0.0).rgb;  // SPEC §5: (21268, 18069, 15658)
  EXPECT_NEAR(zenith.r, 21268.f, 1.f);
  EXPECT_NEAR(zenith.g, 18069.f, 1.f);
  EXPECT_NEAR(zenith.b, 15658.f, 1.f);
}

}  // namespace
}  // namespace tessera
