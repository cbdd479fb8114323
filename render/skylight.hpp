// The light a surface receives besides the sun's beam, and the beam's own colour
// (world.light.skylight, docs/rendering.md, Light). The constant model hands back `ambient` and
// `diffuse` as white. The clear-sky model is a simplified form of Bird & Hulstrom's (1981): Rayleigh
// optical depth 0.0088 λ^-4.05 and aerosol depth τ_a (λ / 550 nm)^-1.3 at three wavelengths (610,
// 550, 465 nm for red, green, blue), the air mass of Kasten & Young (1989); the beam is their
// transmittance, the sky's light on a level surface sin h [0.5 (1 - T_r) + 0.84 (1 - T_a)] (half the
// Rayleigh and most of the aerosol scattering goes forward, down); both scaled so that green with
// the sun at the zenith is `diffuse` and `ambient`. A surface facing down sees the ground, lit by
// beam and sky, times its albedo.
#pragma once

#include <Eigen/Core>

#include "sim/world.hpp"

namespace wingman::render {

struct SkyLight {
  Eigen::Vector3d sky;     // RGB on a surface facing up (the whole sky)
  Eigen::Vector3d ground;  // RGB on a surface facing down (the lit ground); = sky when constant
  Eigen::Vector3d beam;    // RGB of the sun's beam on a surface facing it
};

// For the light's travel direction (its elevation h = asin(-z); below 0.5 deg the clear sky holds
// the beam at 0.5 deg's, where Lambert's cosine has all but put it out).
SkyLight sky_light(const sim::LightSpec& light, const Eigen::Vector3d& travel);

// Kasten & Young's relative optical air mass at the sun's elevation in degrees.
double air_mass(double elevation_deg);

}  // namespace wingman::render
