// Reduction of spectral values in scene files to linear Rec. 709 RGB, as Mitsuba 0.6's RGB build
// does it: integrate against the CIE 1931 colour-matching functions at 1 nm steps over 360-830 nm,
// divide by the integral of y-bar, convert XYZ to linear RGB with Mitsuba's matrix, clamp negatives.
//
// The table below carries the CIE 1931 2-degree observer at 5 nm (every fifth row of
// ../shared/data/sunsky/cie1931_xyz_cmf_360_830.txt, itself copied from Mitsuba's spectrum.cpp);
// the 1 nm values in between are linear interpolations, which changes results by ~1e-3 relative.
#include "scene/xml_values.h"

#include <cmath>

namespace tessera::xml {

namespace {

constexpr int kCieStart = 360, kCieEnd = 830, kCieStep = 5;
constexpr double kCie[][3] = {
    {0.0001299000, 0.000003917000, 0.0006061000},
    {0.0002321000, 0.000006965000, 0.001086000},
    {0.0004149000, 0.00001239000, 0.001946000},
    {0.0007416000, 0.00002202000, 0.003486000},
    {0.001368000, 0.00003900000, 0.006450001},
    {0.002236000, 0.00006400000, 0.01054999},
    {0.004243000, 0.0001200000, 0.02005001},
    {0.007650000, 0.0002170000, 0.03621000},
    {0.01431000, 0.0003960000, 0.06785001},
    {0.02319000, 0.0006400000, 0.1102000},
    {0.04351000, 0.001210000, 0.2074000},
    {0.07763000, 0.002180000, 0.3713000},
    {0.1343800, 0.004000000, 0.6456000},
    {0.2147700, 0.007300000, 1.0390501},
    {0.2839000, 0.01160000, 1.3856000},
    {0.3285000, 0.01684000, 1.6229600},
    {0.3482800, 0.02300000, 1.7470600},
    {0.3480600, 0.02980000, 1.7826000},
    {0.3362000, 0.03800000, 1.7721100},
    {0.3187000, 0.04800000, 1.7441000},
    {0.2908000, 0.06000000, 1.6692000},
    {0.2511000, 0.07390000, 1.5281000},
    {0.1953600, 0.09098000, 1.2876400},
    {0.1421000, 0.1126000, 1.0419000},
    {0.09564000, 0.1390200, 0.8129501},
    {0.05795001, 0.1693000, 0.6162000},
    {0.03201000, 0.2080200, 0.4651800},
    {0.01470000, 0.2586000, 0.3533000},
    {0.004900000, 0.3230000, 0.2720000},
    {0.002400000, 0.4073000, 0.2123000},
    {0.009300000, 0.5030000, 0.1582000},
    {0.02910000, 0.6082000, 0.1117000},
    {0.06327000, 0.7100000, 0.07824999},
    {0.1096000, 0.7932000, 0.05725001},
    {0.1655000, 0.8620000, 0.04216000},
    {0.2257499, 0.9148501, 0.02984000},
    {0.2904000, 0.9540000, 0.02030000},
    {0.3597000, 0.9803000, 0.01340000},
    {0.4334499, 0.9949501, 0.008749999},
    {0.5120501, 1.0000000, 0.005749999},
    {0.5945000, 0.9950000, 0.003900000},
    {0.6784000, 0.9786000, 0.002749999},
    {0.7621000, 0.9520000, 0.002100000},
    {0.8425000, 0.9154000, 0.001800000},
    {0.9163000, 0.8700000, 0.001650001},
    {0.9786000, 0.8163000, 0.001400000},
    {1.0263000, 0.7570000, 0.001100000},
    {1.0567000, 0.6949000, 0.001000000},
    {1.0622000, 0.6310000, 0.0008000000},
    {1.0456000, 0.5668000, 0.0006000000},
    {1.0026000, 0.5030000, 0.0003400000},
    {0.9384000, 0.4412000, 0.0002400000},
    {0.8544499, 0.3810000, 0.0001900000},
    {0.7514000, 0.3210000, 0.0001000000},
    {0.6424000, 0.2650000, 0.00004999999},
    {0.5419000, 0.2170000, 0.00003000000},
    {0.4479000, 0.1750000, 0.00002000000},
    {0.3608000, 0.1382000, 0.00001000000},
    {0.2835000, 0.1070000, 0.000000000000},
    {0.2187000, 0.08160000, 0.0},
    {0.1649000, 0.06100000, 0.0},
    {0.1212000, 0.04458000, 0.0},
    {0.08740000, 0.03200000, 0.0},
    {0.06360000, 0.02320000, 0.0},
    {0.04677000, 0.01700000, 0.0},
    {0.03290000, 0.01192000, 0.0},
    {0.02270000, 0.008210000, 0.0},
    {0.01584000, 0.005723000, 0.0},
    {0.01135916, 0.004102000, 0.0},
    {0.008110916, 0.002929000, 0.0},
    {0.005790346, 0.002091000, 0.0},
    {0.004109457, 0.001484000, 0.0},
    {0.002899327, 0.001047000, 0.0},
    {0.002049190, 0.0007400000, 0.0},
    {0.001439971, 0.0005200000, 0.0},
    {0.0009999493, 0.0003611000, 0.0},
    {0.0006900786, 0.0002492000, 0.0},
    {0.0004760213, 0.0001719000, 0.0},
    {0.0003323011, 0.0001200000, 0.0},
    {0.0002348261, 0.00008480000, 0.0},
    {0.0001661505, 0.00006000000, 0.0},
    {0.0001174130, 0.00004240000, 0.0},
    {0.00008307527, 0.00003000000, 0.0},
    {0.00005870652, 0.00002120000, 0.0},
    {0.00004150994, 0.00001499000, 0.0},
    {0.00002935326, 0.00001060000, 0.0},
    {0.00002067383, 0.000007465700, 0.0},
    {0.00001455977, 0.000005257800, 0.0},
    {0.00001025398, 0.000003702900, 0.0},
    {0.000007221456, 0.000002607800, 0.0},
    {0.000005085868, 0.000001836600, 0.0},
    {0.000003581652, 0.000001293400, 0.0},
    {0.000002522525, 0.0000009109300, 0.0},
    {0.000001776509, 0.0000006415300, 0.0},
    {0.000001251141, 0.0000004518100, 0.0},
};
static_assert(sizeof(kCie) / sizeof(kCie[0]) == (kCieEnd - kCieStart) / kCieStep + 1);

// Colour-matching functions at integer wavelength `lambda` in [360, 830].
void cmf(int lambda, double& x, double& y, double& z) {
  int i = (lambda - kCieStart) / kCieStep;
  int rem = (lambda - kCieStart) % kCieStep;
  if (rem == 0) {
    x = kCie[i][0], y = kCie[i][1], z = kCie[i][2];
    return;
  }
  double t = double(rem) / kCieStep;
  x = kCie[i][0] + t * (kCie[i + 1][0] - kCie[i][0]);
  y = kCie[i][1] + t * (kCie[i + 1][1] - kCie[i][1]);
  z = kCie[i][2] + t * (kCie[i + 1][2] - kCie[i][2]);
}

template <typename F>
Rgb integrate(F&& value_at) {
  double x = 0, y = 0, z = 0, y_sum = 0;
  for (int lambda = kCieStart; lambda <= kCieEnd; ++lambda) {
    double cx, cy, cz;
    cmf(lambda, cx, cy, cz);
    double v = value_at(double(lambda));
    x += cx * v;
    y += cy * v;
    z += cz * v;
    y_sum += cy;
  }
  x /= y_sum;
  y /= y_sum;
  z /= y_sum;
  // Mitsuba 0.6 Spectrum::fromXYZ (ITU-R BT.709 primaries, D65 white).
  double r = 3.240479 * x - 1.537150 * y - 0.498535 * z;
  double g = -0.969256 * x + 1.875991 * y + 0.041556 * z;
  double b = 0.055648 * x - 0.204043 * y + 1.057311 * z;
  return Rgb(float(std::max(r, 0.0)), float(std::max(g, 0.0)), float(std::max(b, 0.0)));
}

}  // namespace

Rgb spectrum_to_rgb(const std::vector<double>& wavelengths, const std::vector<double>& values) {
  // Piecewise linear between the given samples and zero outside them (InterpolatedSpectrum).
  return integrate([&](double lambda) {
    size_t n = wavelengths.size();
    if (n == 0 || lambda < wavelengths.front() || lambda > wavelengths.back()) return 0.0;
    size_t i = 0;
    while (wavelengths[i] < lambda) ++i;  // terminates: lambda <= wavelengths.back()
    if (wavelengths[i] == lambda) return values[i];
    double t = (lambda - wavelengths[i - 1]) / (wavelengths[i] - wavelengths[i - 1]);
    return values[i - 1] + t * (values[i] - values[i - 1]);
  });
}

Rgb blackbody_to_rgb(double kelvin) {
  // Mitsuba 0.6 BlackBodySpectrum::sample: spectral exitance in W cm^-2 nm^-1.
  return integrate([&](double lambda_nm) {
    const double lambda = lambda_nm * 1e-9;
    const double c = 299792458, h = 6.62607095e-34, k = 1.3807e-23;
    const double pi = 3.14159265358979323846;
    return (2 * pi * h * c * c) * std::pow(lambda, -5.0) /
           (1e9 * 1e4 * (std::exp((h / k) * c / (lambda * kelvin)) - 1.0));
  });
}

}  // namespace tessera::xml
