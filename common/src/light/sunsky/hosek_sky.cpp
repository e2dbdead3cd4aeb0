#include "tessera/light/sunsky/hosek_sky.h"

#include "light/sunsky/sunsky_tables.h"
#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera {

namespace {

constexpr double kPiD = 3.14159265358979323846;
// Integral of CIE ybar over 360..830 nm: turns the RGB-fit output into per-nm radiance (SPEC §4).
constexpr double kCieYIntegral = 106.856980;
constexpr int kChannels = 3, kAlbedos = 2, kTurbidities = 10, kControlPoints = 6, kParams = 9;

struct HosekData {
  std::vector<double> coeffs;     // [3][2][10][6][9]
  std::vector<double> radiance;   // [3][2][10][6]
};

const HosekData& hosek_data() {
  static const HosekData data{
      sunsky::table_values("hosek_rgb_coeffs", size_t(kChannels * kAlbedos * kTurbidities * kControlPoints * kParams)),
      sunsky::table_values("hosek_rgb_radiance", size_t(kChannels * kAlbedos * kTurbidities * kControlPoints))};
  return data;
}

}  // namespace

HosekSky::HosekSky(double turbidity, Rgb albedo, double sun_theta) : sun_theta_(sun_theta) {
  TESSERA_CHECK(turbidity >= 1.0 && turbidity <= 10.0);
  TESSERA_CHECK(sun_theta >= 0.0 && sun_theta <= 0.5 * kPiD + 1e-9);
  const HosekData& data = hosek_data();
  const double elevation = std::max(0.0, 0.5 * kPiD - sun_theta);
  const double x = std::cbrt(elevation / (0.5 * kPiD));
  double bernstein[kControlPoints];
  const double binomial[kControlPoints] = {1, 5, 10, 10, 5, 1};
  for (int k = 0; k < kControlPoints; ++k)
    bernstein[k] = binomial[k] * std::pow(x, k) * std::pow(1.0 - x, kControlPoints - 1 - k);

  const int t0 = std::clamp(int(turbidity), 1, kTurbidities);
  const double frac = turbidity - double(t0);
  for (int c = 0; c < kChannels; ++c) {
    const double rho = std::clamp(double(albedo[c]), 0.0, 1.0);
    double lm = 0.0;
    for (int a = 0; a < kAlbedos; ++a)
      for (int dt = 0; dt < 2; ++dt) {
        const int t = t0 + dt;
        if (t > kTurbidities) continue;  // T = 10: no upper neighbour
        const double w = (a == 0 ? 1.0 - rho : rho) * (dt == 0 ? 1.0 - frac : frac);
        if (w == 0.0) continue;
        const size_t block = size_t((c * kAlbedos + a) * kTurbidities + (t - 1)) * kControlPoints;
        for (int k = 0; k < kControlPoints; ++k) {
          const double bw = w * bernstein[k];
          for (int p = 0; p < kParams; ++p) params_[c][p] += bw * data.coeffs[(block + size_t(k)) * kParams + size_t(p)];
          lm += bw * data.radiance[block + size_t(k)];
        }
      }
    radiance_[c] = lm / kCieYIntegral;
  }
}

double HosekSky::channel(int c, double cos_theta, double gamma) const {
  const double* q = params_[c];  // A B C D E F G I H
  const double cos_gamma = std::cos(gamma);
  const double cos2 = cos_gamma * cos_gamma;
  const double g = q[8];
  const double mie = (1.0 + cos2) / std::pow(1.0 + g * g - 2.0 * g * cos_gamma, 1.5);
  const double f = (1.0 + q[0] * std::exp(q[1] / (cos_theta + 0.01))) *
                   (q[2] + q[3] * std::exp(q[4] * gamma) + q[5] * cos2 + q[6] * mie + q[7] * std::sqrt(cos_theta));
  return std::max(0.0, f * radiance_[c]);
}

Rgb HosekSky::eval(double theta, double gamma) const {
  const double cos_theta = std::cos(theta);
  if (!(cos_theta > 0.0)) return Rgb(0.f);
  return {float(channel(0, cos_theta, gamma)), float(channel(1, cos_theta, gamma)), float(channel(2, cos_theta, gamma))};
}

Rgb HosekSky::eval_above(double theta, double gamma) const {
  const double cos_theta = std::max(0.0, std::cos(theta));
  return {float(channel(0, cos_theta, gamma)), float(channel(1, cos_theta, gamma)), float(channel(2, cos_theta, gamma))};
}

Rgb HosekSky::eval_direction(double theta, double phi, double sun_phi, double stretch) const {
  const double t = theta / stretch;
  const double cos_gamma = std::cos(t) * std::cos(sun_theta_) + std::sin(t) * std::sin(sun_theta_) * std::cos(phi - sun_phi);
  return eval(t, std::acos(std::clamp(cos_gamma, -1.0, 1.0)));
}

}  // namespace tessera
