// The Hosek-Wilkie 2012 sky (ArHosekSkyModel v1.2, RGB dataset) as Mitsuba 0.5/0.6's RGB build
// evaluates it (data/sunsky SPEC §4). The coefficients are embedded from common/data/sunsky/
// (hosek_rgb_coeffs.txt, hosek_rgb_radiance.txt; BSD licence of Hosek and Wilkie, see their headers).
//
// Units: W m^-2 sr^-1 nm^-1, Mitsuba's (model output / 106.856980, the integral of CIE ybar), so
// that sky and sun add up. Angles are in the emitter's Y-up frame (light/sunsky/solar_position.h).
#pragma once

#include "tessera/core/rgb.h"

namespace tessera {

class HosekSky {
 public:
  /// `turbidity` in [1, 10], per-channel ground `albedo` in [0, 1], sun zenith angle in
  /// [0, pi/2] (checked: the model is undefined for a sun below the horizon).
  HosekSky(double turbidity, Rgb albedo, double sun_theta);

  /// Radiance towards a view direction of zenith angle `theta` (already divided by the stretch)
  /// at angle `gamma` from the sun; zero when cos(theta) <= 0 (below the horizon).
  Rgb eval(double theta, double gamma) const;
  /// eval() without the horizon cut-off: the model continued to cos(theta) = max(cos, 0). For
  /// the texels of a baked map that lie exactly on the horizon (see light/sunsky/sunsky_bake.h).
  Rgb eval_above(double theta, double gamma) const;

  /// Radiance towards a view direction (zenith theta, azimuth phi) for a sun at (sun_theta,
  /// sun_phi), with Mitsuba's `stretch` s: theta' = theta / s, gamma from theta' and the sun.
  Rgb eval_direction(double theta, double phi, double sun_phi, double stretch) const;

  double sun_theta() const { return sun_theta_; }

 private:
  double channel(int c, double cos_theta, double gamma) const;

  double params_[3][9] = {};  // A B C D E F G I H per channel
  double radiance_[3] = {};   // L_M per channel, already divided by 106.856980
  double sun_theta_ = 0;
};

}  // namespace tessera
