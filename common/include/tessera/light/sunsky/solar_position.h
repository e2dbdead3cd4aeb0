// Where the sun is, for Mitsuba 0.5/0.6's `sun`, `sky` and `sunsky` emitters (data/sunsky SPEC §3).
//
// The emitters' local frame is Y-up: a direction with zenith angle theta (from +y) and azimuth phi is
//   d(theta, phi) = (sin phi sin theta, cos theta, -cos phi sin theta),
// i.e. the latitude-longitude convention of light/envmap.h (phi = 0 looks down -z, phi = 90 deg along
// +x). Solar azimuth is measured from north through east, so east = +x, north = -z, south = +z.
#pragma once

#include "tessera/core/vec.h"

namespace tessera {

/// Date, local time and place (Mitsuba's defaults: Tokyo, 2010-07-10 15:00, timezone +9).
struct SunTimeAndPlace {
  int year = 2010, month = 7, day = 10;
  double hour = 15, minute = 0, second = 0;
  double latitude = 35.6894, longitude = 139.6917;  // degrees, north and east positive
  double timezone = 9;                              // hours east of UTC
};

/// Sun position as zenith angle and azimuth in radians (azimuth in [0, 2 pi)).
struct SunAngles {
  double theta = 0, phi = 0;
};

/// The PSA algorithm (Blanco-Muriel et al., Solar Energy 2001) with Mitsuba's parallax
/// correction; integer divisions truncate toward zero as in the original.
SunAngles solar_position(const SunTimeAndPlace& when);

/// Angles of a (local-frame) direction towards the sun; `d` need not be normalised.
SunAngles sun_angles_from_direction(Vec3 d);

/// d(theta, phi) of the frame above (unit length).
Vec3 sunsky_direction(double theta, double phi);

}  // namespace tessera
