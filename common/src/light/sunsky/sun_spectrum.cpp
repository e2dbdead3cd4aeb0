#include "tessera/light/sunsky/sun_spectrum.h"

#include "light/sunsky/sunsky_tables.h"
#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera {

namespace {

constexpr double kPiD = 3.14159265358979323846;

/// A tabulated function of wavelength, zero outside its range, linear (or Mitsuba 0.6's swapped
/// linear) inside.
struct Curve {
  std::vector<double> x, y;

  Curve() = default;
  /// From rows of `stride` values, x first; y is column `column`.
  Curve(const std::vector<double>& rows, size_t stride, size_t column) {
    for (size_t i = 0; i + stride <= rows.size(); i += stride) {
      x.push_back(rows[i]);
      y.push_back(rows[i + column]);
    }
  }

  double eval(double l, SunInterpolation interp) const {
    if (x.size() < 2 || l < x.front() || l > x.back()) return 0.0;
    size_t i = size_t(std::upper_bound(x.begin(), x.end(), l) - x.begin());
    if (i == 0) return 0.0;
    if (x[i - 1] == l) return y[i - 1];  // a node: exact in both variants
    if (i >= x.size()) return y.back();
    const double t = (l - x[i - 1]) / (x[i] - x[i - 1]);
    return interp == SunInterpolation::Linear ? (1.0 - t) * y[i - 1] + t * y[i] : (1.0 - t) * y[i] + t * y[i - 1];
  }
};

struct SunTables {
  Curve solar, ozone, mixed_gas, water_vapour;
  Curve cie[3];
  double cie_y_integral = 0;  // trapezoids on the 1 nm table: 106.856978
};

const SunTables& sun_tables() {
  static const SunTables t = [] {
    SunTables s;
    s.solar = Curve(sunsky::table_values("sun_solar_radiance", 38 * 2), 2, 1);
    s.ozone = Curve(sunsky::table_values("sun_ozone_ko", 64 * 2), 2, 1);
    s.mixed_gas = Curve(sunsky::table_values("sun_mixedgas_kg", 4 * 2), 2, 1);
    s.water_vapour = Curve(sunsky::table_values("sun_watervapor_kwa", 13 * 2), 2, 1);
    const std::vector<double> cmf = sunsky::table_values("cie1931_xyz_cmf_360_830", 471 * 4);
    for (int c = 0; c < 3; ++c) s.cie[c] = Curve(cmf, 4, size_t(c + 1));
    const Curve& ybar = s.cie[1];
    for (size_t i = 0; i + 1 < ybar.x.size(); ++i)
      s.cie_y_integral += 0.5 * (ybar.y[i] + ybar.y[i + 1]) * (ybar.x[i + 1] - ybar.x[i]);
    return s;
  }();
  return t;
}

}  // namespace

double sun_solid_angle() { return 2.0 * kPiD * (1.0 - std::cos(kSunHalfAngle)); }

SunRadiance sun_radiance(double turbidity, double sun_theta, SunInterpolation interp) {
  TESSERA_CHECK(turbidity >= 1.0 && turbidity <= 10.0);
  const SunTables& t = sun_tables();

  // Transmitted spectrum at 350, 355, ..., 800 nm.
  const double beta = 0.04608365822050 * turbidity - 0.04586025928522;
  const double theta_deg = sun_theta * 180.0 / kPiD;
  const double m = 1.0 / (std::cos(sun_theta) + 0.15 * std::pow(93.885 - theta_deg, -1.253));
  constexpr double kOzone = 0.35, kWater = 2.0, kAlpha = 1.3;
  Curve spectrum;
  for (int i = 0; i < 91; ++i) {
    const double l = 350.0 + 5.0 * i, mu = l / 1000.0;
    const double ko = t.ozone.eval(l, interp), kg = t.mixed_gas.eval(l, interp), kwa = t.water_vapour.eval(l, interp);
    const double tau_r = std::exp(-m * 0.008735 * std::pow(mu, -4.08));
    const double tau_a = std::exp(-m * beta * std::pow(mu, -kAlpha));
    const double tau_o = std::exp(-m * ko * kOzone);
    const double tau_g = std::exp(-1.41 * kg * m / std::pow(1.0 + 118.93 * kg * m, 0.45));
    const double tau_w = std::exp(-0.2385 * kwa * kWater * m / std::pow(1.0 + 20.07 * kwa * kWater * m, 0.45));
    spectrum.x.push_back(l);
    spectrum.y.push_back(t.solar.eval(l, interp) * tau_r * tau_a * tau_o * tau_g * tau_w);
  }

  // Both factors are linear on every 1 nm interval of the CIE grid (the 5 nm nodes are on it),
  // so Simpson's rule per interval is exact.
  SunRadiance out;
  for (int c = 0; c < 3; ++c) {
    const Curve& cmf = t.cie[c];
    double sum = 0.0;
    for (size_t i = 0; i + 1 < cmf.x.size(); ++i) {
      const double a = cmf.x[i], b = cmf.x[i + 1], mid = 0.5 * (a + b);
      auto f = [&](double l) { return spectrum.eval(l, interp) * cmf.eval(l, interp); };
      // Endpoints as limits from inside the interval: under the swapped rule a curve is linear on
      // each open interval but takes another value at the node itself.
      constexpr double kInside = 1e-9;
      const double fa = f(a + kInside), fb = f(b - kInside), fm = f(mid);
      sum += (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    }
    out.xyz[c] = sum / t.cie_y_integral;
  }
  const double x = out.xyz[0], y = out.xyz[1], z = out.xyz[2];
  const double r = 3.240479 * x - 1.537150 * y - 0.498535 * z;
  const double g = -0.969256 * x + 1.875991 * y + 0.041556 * z;
  const double b = 0.055648 * x - 0.204043 * y + 1.057311 * z;
  out.rgb = Rgb(float(std::max(0.0, r)), float(std::max(0.0, g)), float(std::max(0.0, b)));
  return out;
}

}  // namespace tessera
