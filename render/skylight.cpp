#include "render/skylight.hpp"

#include <algorithm>
#include <cmath>

namespace wingman::render {

namespace {

constexpr double kPi = 3.14159265358979323846;
const Eigen::Vector3d kWavelengthUm{0.610, 0.550, 0.465};

struct Transmittance {
  Eigen::Vector3d rayleigh, aerosol;
};

Transmittance transmittance(double m, double aerosol_depth) {
  Transmittance t;
  for (int c = 0; c < 3; ++c) {
    const double l = kWavelengthUm[c];
    t.rayleigh[c] = std::exp(-0.0088 * std::pow(l, -4.05) * m);
    t.aerosol[c] = std::exp(-aerosol_depth * std::pow(l / 0.55, -1.3) * m);
  }
  return t;
}

// Sky light on a level surface per unit of the light above the atmosphere.
Eigen::Vector3d level_sky(const Transmittance& t, double sin_h) {
  return sin_h * (0.5 * (Eigen::Vector3d::Ones() - t.rayleigh) + 0.84 * (Eigen::Vector3d::Ones() - t.aerosol));
}

}  // namespace

double air_mass(double elevation_deg) {
  const double h = std::clamp(elevation_deg, 0.0, 90.0);
  return 1.0 / (std::sin(h * kPi / 180) + 0.50572 * std::pow(h + 6.07995, -1.6364));
}

SkyLight sky_light(const sim::LightSpec& light, const Eigen::Vector3d& travel) {
  if (light.skylight.model == sim::SkylightSpec::Model::Constant) {
    const Eigen::Vector3d a = Eigen::Vector3d::Constant(light.ambient);
    return {a, a, Eigen::Vector3d::Constant(light.diffuse)};
  }
  const double tau = light.skylight.aerosol_depth;
  const double h = std::max(0.5, std::asin(std::clamp(-travel.normalized().z(), -1.0, 1.0)) * 180 / kPi);
  const Transmittance zenith = transmittance(air_mass(90), tau), now = transmittance(air_mass(h), tau);
  const double beam_scale = light.diffuse / (zenith.rayleigh[1] * zenith.aerosol[1]);
  const double sky_scale = light.ambient / level_sky(zenith, 1)[1];
  SkyLight s;
  s.beam = beam_scale * now.rayleigh.cwiseProduct(now.aerosol);
  const double sin_h = std::sin(h * kPi / 180);
  s.sky = sky_scale * level_sky(now, sin_h);
  s.ground = light.skylight.ground_albedo * (s.beam * sin_h + s.sky);
  return s;
}

}  // namespace wingman::render
