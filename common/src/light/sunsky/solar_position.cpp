#include "tessera/light/sunsky/solar_position.h"

#include <algorithm>
#include <cmath>

namespace tessera {

namespace {
constexpr double kPiD = 3.14159265358979323846;

double wrap_2pi(double a) {
  a = std::fmod(a, 2.0 * kPiD);
  return a < 0.0 ? a + 2.0 * kPiD : a;
}
}  // namespace

SunAngles solar_position(const SunTimeAndPlace& w) {
  // Universal time in hours, then the Julian day by integer arithmetic (truncating divisions).
  const double h = w.hour - w.timezone + (w.minute + w.second / 60.0) / 60.0;
  const int a = (w.month - 14) / 12;
  const int julian = (1461 * (w.year + 4800 + a)) / 4 + (367 * (w.month - 2 - 12 * a)) / 12 -
                     (3 * ((w.year + 4900 + a) / 100)) / 4 + w.day - 32075;
  const double n = double(julian) - 0.5 + h / 24.0 - 2451545.0;

  // Ecliptic coordinates.
  const double omega = 2.1429 - 0.0010394594 * n;
  const double mean_longitude = 4.8950630 + 0.017202791698 * n;
  const double mean_anomaly = 6.2400600 + 0.0172019699 * n;
  const double ecliptic_longitude = mean_longitude + 0.03341607 * std::sin(mean_anomaly) +
                                    0.00034894 * std::sin(2.0 * mean_anomaly) - 0.0001134 -
                                    0.0000203 * std::sin(omega);
  const double obliquity = 0.4090928 - 6.2140e-9 * n + 0.0000396 * std::cos(omega);

  // Celestial coordinates.
  const double sin_el = std::sin(ecliptic_longitude);
  const double right_ascension =
      wrap_2pi(std::atan2(std::cos(obliquity) * sin_el, std::cos(ecliptic_longitude)));
  const double declination = std::asin(std::sin(obliquity) * sin_el);

  // Local coordinates.
  const double gmst = 6.6974243242 + 0.0657098283 * n + h;
  const double hour_angle = (15.0 * gmst + w.longitude) * kPiD / 180.0 - right_ascension;
  const double lat = w.latitude * kPiD / 180.0;
  const double cos_ha = std::cos(hour_angle);
  double theta = std::acos(std::clamp(
      std::cos(lat) * cos_ha * std::cos(declination) + std::sin(declination) * std::sin(lat), -1.0, 1.0));
  const double phi = wrap_2pi(
      std::atan2(-std::sin(hour_angle), std::tan(declination) * std::cos(lat) - std::sin(lat) * cos_ha));
  // Parallax: the observer stands on the earth's surface, not at its centre.
  theta += (6371.01 / 149597890.0) * std::sin(theta);
  return {theta, phi};
}

SunAngles sun_angles_from_direction(Vec3 d) {
  const double x = d.x, y = d.y, z = d.z;
  const double len = std::sqrt(x * x + y * y + z * z);
  if (!(len > 0.0)) return {};
  return {std::acos(std::clamp(y / len, -1.0, 1.0)), wrap_2pi(std::atan2(x, -z))};
}

Vec3 sunsky_direction(double theta, double phi) {
  const double s = std::sin(theta);
  return {float(std::sin(phi) * s), float(std::cos(theta)), float(-std::cos(phi) * s)};
}

}  // namespace tessera
