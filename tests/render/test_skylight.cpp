// The clear-sky light against its formulas (render/skylight.hpp): Kasten & Young's air mass, the
// zenith values the scenario gives, a beam that dims and reddens and a sky that dims as the sun
// sinks; and, with both backends, the renderer lighting a level surface with sky and beam and a
// surface facing down with the ground's light alone.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "render/renderer.hpp"
#include "render/skylight.hpp"
#include "geometry/rotation.hpp"
#include "render_test_support.hpp"

namespace wingman::render {
namespace {

using testing::backend_name;

constexpr double kPi = 3.14159265358979323846;

sim::LightSpec clear_sky() {
  sim::LightSpec l;
  l.ambient = 0.4;
  l.diffuse = 0.7;
  l.skylight.model = sim::SkylightSpec::Model::ClearSky;
  return l;
}

Eigen::Vector3d travel_at(double elevation_deg) {
  const double h = elevation_deg * kPi / 180;
  return {std::cos(h), 0, -std::sin(h)};
}

TEST(SkyLight, AirMassIsKastenAndYoungs) {
  EXPECT_NEAR(air_mass(90), 1.0, 1e-3);
  EXPECT_NEAR(air_mass(30), 1.995, 2e-3);
  EXPECT_NEAR(air_mass(0), 37.92, 0.01);
}

TEST(SkyLight, ConstantSkyIsTheGivenWhiteLight) {
  sim::LightSpec l;
  l.ambient = 0.3;
  l.diffuse = 0.8;
  const SkyLight s = sky_light(l, travel_at(20));
  EXPECT_EQ(s.sky, Eigen::Vector3d::Constant(0.3));
  EXPECT_EQ(s.ground, s.sky);
  EXPECT_EQ(s.beam, Eigen::Vector3d::Constant(0.8));
}

TEST(SkyLight, ClearSkyAtTheZenithIsTheGivenLightInGreenAndBlueInTheShade) {
  const SkyLight s = sky_light(clear_sky(), travel_at(90));
  EXPECT_NEAR(s.sky[1], 0.4, 1e-9);
  EXPECT_NEAR(s.beam[1], 0.7, 1e-9);
  EXPECT_GT(s.sky[2], 1.3 * s.sky[1]);
  EXPECT_LT(s.sky[0], s.sky[1]);
  EXPECT_NEAR(s.ground[1], 0.15 * (0.7 + 0.4), 1e-9);
}

TEST(SkyLight, TheBeamDimsAndReddensAsTheSunSinks) {
  double last_ratio = 0, last_beam = 1e9, last_sky = 1e9;
  for (double h : {90.0, 60.0, 30.0, 15.0, 5.0}) {
    const SkyLight s = sky_light(clear_sky(), travel_at(h));
    EXPECT_GT(s.beam[0] / s.beam[2], last_ratio) << h;
    EXPECT_LT(s.beam[1], last_beam) << h;
    EXPECT_LT(s.sky[1], last_sky) << h;
    last_ratio = s.beam[0] / s.beam[2], last_beam = s.beam[1], last_sky = s.sky[1];
  }
  // At 30 deg: exp(-tau_g (m - 1)) of the zenith beam, tau_g = Rayleigh 0.0088 0.55^-4.05 + aerosol 0.1.
  const double tau_g = 0.0088 * std::pow(0.55, -4.05) + 0.1;
  EXPECT_NEAR(sky_light(clear_sky(), travel_at(30)).beam[1], 0.7 * std::exp(-tau_g * (air_mass(30) - air_mass(90))), 1e-9);
}

// A level white square lit from 40 deg up, and a white square 5 m up facing down, seen from below.
class SkyLightRenderTest : public ::testing::TestWithParam<GlBackend> {};

TEST_P(SkyLightRenderTest, SurfacesTakeTheSkyFacingUpAndTheGroundFacingDown) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  Scene s;
  s.materials.push_back(Material{});
  s.static_meshes.push_back(testing::square({0, 0, 0}, 40, {1, 1, 1}, 0));
  Mesh ceiling = testing::square({0, 0, 5}, 40, {1, 1, 1}, 0);
  for (std::size_t i = 2; i < ceiling.normals.size(); i += 3) ceiling.normals[i] = -1;
  s.light = clear_sky();
  s.light.direction = travel_at(40);
  s.msaa = 1;
  const SkyLight want = sky_light(s.light, s.light.direction);
  const geometry::PinholeCamera cam(200, 200, 99.5, 99.5, 200, 200);
  Renderer floor_only(ctx, s);
  const cv::Vec3b down = floor_only.render({cam, {geometry::nadir_R_CW(), {0, 0, 3}}}).rgb.at<cv::Vec3b>(100, 100);
  s.static_meshes.push_back(ceiling);
  Renderer both(ctx, s);
  const cv::Vec3b up = both.render({cam, {Eigen::Matrix3d::Identity(), {0, 0, 2}}}).rgb.at<cv::Vec3b>(100, 100);
  const double sin_h = std::sin(40 * kPi / 180);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(down[c], 255 * (want.sky[c] + want.beam[c] * sin_h), 1.0) << c;
    EXPECT_NEAR(up[c], 255 * want.ground[c], 1.0) << c;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, SkyLightRenderTest,
                         ::testing::Values(GlBackend::Egl, GlBackend::OsMesa), backend_name);

}  // namespace
}  // namespace wingman::render
