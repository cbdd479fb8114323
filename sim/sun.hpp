// Where the sun is: NOAA's solar-position equations (the "General Solar Position Calculations" of
// NOAA's Global Monitoring Laboratory; about 0.1 deg against the full ephemeris between 1950 and
// 2050), for a place and a UTC time, in the world frame (x east, y north, z up).
#pragma once

#include <Eigen/Core>

namespace wingman::sim {

// Unit vector from the ground toward the sun. latitude, longitude: degrees (north, east positive);
// day_of_year: 1-366; time_utc: hours.
Eigen::Vector3d sun_vector(double latitude, double longitude, double day_of_year, double time_utc);

}  // namespace wingman::sim
