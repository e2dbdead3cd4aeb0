// Mitsuba 0.5/0.6's sun (data/sunsky SPEC §5): the extraterrestrial solar spectrum attenuated by
// Rayleigh, aerosol, ozone, mixed-gas and water-vapour transmittance (Preetham et al. 1999 after
// Iqbal 1983), reduced to linear sRGB through CIE 1931 XYZ. Tables embedded from common/data/sunsky/.
#pragma once

#include "tessera/core/rgb.h"

namespace tessera {

/// Half-angle of the sun disk: Mitsuba's constant 0.5358 deg is its diameter.
inline constexpr double kSunHalfAngle = 0.5 * 0.5358 * 3.14159265358979323846 / 180.0;
/// Solid angle of the disk, 2 pi (1 - cos kSunHalfAngle) = 6.8683e-5 sr.
double sun_solid_angle();

/// Which in-interval interpolation the spectral tables use. Mitsuba's 0.5.0/0.6.0 releases swapped
/// the endpoints inside an interval ((1-t) f_right + t f_left; fixed upstream 2020-01-31).
enum class SunInterpolation { Linear, Mitsuba06Swapped };

struct SunRadiance {
  Rgb rgb;             // linear sRGB radiance of the disk, W m^-2 sr^-1 nm^-1, negatives clamped
  double xyz[3] = {};  // CIE XYZ before the RGB matrix (same units)
};

/// Disk radiance (before sunScale) for `turbidity` and sun zenith angle `sun_theta` (radians,
/// before stretch). Exact quadrature of the piecewise-linear product on the 1 nm CIE grid.
SunRadiance sun_radiance(double turbidity, double sun_theta, SunInterpolation interp = SunInterpolation::Linear);

}  // namespace tessera
