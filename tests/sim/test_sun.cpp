// The sun's position against what the sky does: at the June solstice the noon sun at 45 deg N is
// 68.4 deg up in the south, at the equinox on the equator it is overhead, it rises in the east,
// is down at midnight, and noon comes an hour earlier 15 deg further east.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/sun.hpp"

namespace wingman::sim {
namespace {

double elevation_deg(const Eigen::Vector3d& s) { return std::asin(s.z()) * 180 / M_PI; }

// The UTC hour of the highest sun, to the minute.
double noon(double lat, double lon, double day) {
  double best = 0, best_up = -2;
  for (int m = 0; m < 24 * 60; ++m) {
    const double up = sun_vector(lat, lon, day, m / 60.0).z();
    if (up > best_up) best_up = up, best = m / 60.0;
  }
  return best;
}

TEST(Sun, NoonAtTheSolsticeAndTheEquinoxIsWhereTheDeclinationPutsIt) {
  const double t = noon(45, 0, 172);
  const Eigen::Vector3d s = sun_vector(45, 0, 172, t);
  EXPECT_NEAR(elevation_deg(s), 90 - 45 + 23.44, 0.3);
  EXPECT_LT(s.y(), 0);                 // in the south
  EXPECT_NEAR(s.x(), 0, 0.01);         // neither east nor west
  EXPECT_NEAR(t, 12.0, 5.0 / 60);      // the equation of time is under 3 minutes in June
  EXPECT_NEAR(elevation_deg(sun_vector(0, 0, 80, noon(0, 0, 80))), 90, 1.0);
}

TEST(Sun, RisesInTheEastIsDownAtMidnightAndNoonMovesWithLongitude) {
  const Eigen::Vector3d morning = sun_vector(8.48, -13.23, 80, 8.0);
  EXPECT_GT(morning.x(), 0.5);  // east
  EXPECT_GT(morning.z(), 0);
  EXPECT_LT(sun_vector(8.48, -13.23, 80, 0.9).z(), 0);  // local midnight
  EXPECT_NEAR(noon(30, 0, 120) - noon(30, 15, 120), 1.0, 2.0 / 60);
  EXPECT_NEAR(sun_vector(30, 0, 120, 9).norm(), 1.0, 1e-12);
}

}  // namespace
}  // namespace wingman::sim
