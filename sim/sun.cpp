#include "sim/sun.hpp"

#include <cmath>

namespace wingman::sim {

Eigen::Vector3d sun_vector(double latitude, double longitude, double day_of_year, double time_utc) {
  const double deg = M_PI / 180;
  const double g = 2 * M_PI / 365 * (day_of_year - 1 + (time_utc - 12) / 24);  // fractional year
  const double eqtime = 229.18 * (0.000075 + 0.001868 * std::cos(g) - 0.032077 * std::sin(g) -
                                  0.014615 * std::cos(2 * g) - 0.040849 * std::sin(2 * g));  // minutes
  const double decl = 0.006918 - 0.399912 * std::cos(g) + 0.070257 * std::sin(g) - 0.006758 * std::cos(2 * g) +
                      0.000907 * std::sin(2 * g) - 0.002697 * std::cos(3 * g) + 0.00148 * std::sin(3 * g);
  const double true_solar_minutes = time_utc * 60 + eqtime + 4 * longitude;
  const double hour_angle = (true_solar_minutes / 4 - 180) * deg;  // 0 at solar noon, + after it
  const double lat = latitude * deg;
  return Eigen::Vector3d(-std::cos(decl) * std::sin(hour_angle),
                         std::cos(lat) * std::sin(decl) - std::sin(lat) * std::cos(decl) * std::cos(hour_angle),
                         std::sin(lat) * std::sin(decl) + std::cos(lat) * std::cos(decl) * std::cos(hour_angle))
      .normalized();
}

}  // namespace wingman::sim
