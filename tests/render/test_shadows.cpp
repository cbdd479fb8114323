// Shadows from the sun, with both backends: a box's shadow falls on the ground where geometry
// puts it (its outline cast along the light), holds the ambient light only, and the lit ground
// keeps the brightness it has without shadows; a UAV body is seen and casts its shadow.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cstdio>

#include "geometry/rotation.hpp"
#include "render/renderer.hpp"
#include "render/shutter.hpp"
#include "render_test_support.hpp"

namespace wingman::render {
namespace {

using testing::backend_name;

// An axis-aligned box [x0, x1] x [y0, y1] x [0, h], lit, white.
Mesh box(double x0, double x1, double y0, double y1, double h) {
  Mesh m;
  const Eigen::Vector3d c(1, 1, 1);
  auto face = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& d, const Eigen::Vector3d& n) {
    const auto k = static_cast<std::uint32_t>(m.vertex_count());
    m.add(a, n, {0, 0}, c);
    m.add(b, n, {1, 0}, c);
    m.add(b + d - a, n, {1, 1}, c);
    m.add(d, n, {0, 1}, c);
    m.indices.insert(m.indices.end(), {k, k + 1, k + 2, k, k + 2, k + 3});
  };
  face({x0, y0, h}, {x1, y0, h}, {x0, y1, h}, {0, 0, 1});
  face({x0, y0, 0}, {x1, y0, 0}, {x0, y0, h}, {0, -1, 0});
  face({x0, y1, 0}, {x1, y1, 0}, {x0, y1, h}, {0, 1, 0});
  face({x0, y0, 0}, {x0, y1, 0}, {x0, y0, h}, {-1, 0, 0});
  face({x1, y0, 0}, {x1, y1, 0}, {x1, y0, h}, {1, 0, 0});
  return m;
}

Scene shadow_scene(bool shadows) {
  Scene s;
  s.materials.push_back(Material{});  // plain white, lit
  s.static_meshes.push_back(testing::square({0, 0, 0}, 60, {1, 1, 1}, 0));
  s.static_meshes.push_back(box(-1, 1, -1, 1, 4));
  s.static_meshes.back().material = 0;
  s.light.direction = {1, 0, -1};  // 45 deg up, from the west: the shadow runs 4 m east
  s.light.shadows = shadows;
  s.msaa = 1;
  return s;
}

class ShadowTest : public ::testing::TestWithParam<GlBackend> {};

TEST_P(ShadowTest, ABoxsShadowFallsWhereTheLightCastsItsOutline) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const geometry::PinholeCamera cam(500, 500, 199.5, 199.5, 400, 400);  // 6 cm a pixel at 30 m
  const CameraView view{cam, {geometry::nadir_R_CW(), {2, 0, 30}}};
  Renderer lit(ctx, shadow_scene(false)), shadowed(ctx, shadow_scene(true));
  cv::Mat a, b;
  cv::cvtColor(lit.render(view).rgb, a, cv::COLOR_RGB2GRAY);
  cv::cvtColor(shadowed.render(view).rgb, b, cv::COLOR_RGB2GRAY);
  auto at = [&](const cv::Mat& img, double x, double y) {
    const auto uv = cam.project(view.pose.to_camera({x, y, 0}));
    return static_cast<double>(img.at<std::uint8_t>(static_cast<int>(std::lround(uv->y())), static_cast<int>(std::lround(uv->x()))));
  };
  const double ambient = 255 * 0.45, sunlit = 255 * (0.45 + 0.65 * std::sqrt(0.5));
  for (const auto& [x, y] : {std::pair{3.0, 0.0}, {4.5, 0.5}, {1.5, -0.8}}) EXPECT_NEAR(at(b, x, y), ambient, 2) << x << ", " << y;
  for (const auto& [x, y] : {std::pair{6.0, 0.0}, {3.0, 1.5}, {-2.0, 0.0}, {5.5, -1.4}}) {
    EXPECT_NEAR(at(b, x, y), sunlit, 2) << x << ", " << y;
    EXPECT_NEAR(at(b, x, y), at(a, x, y), 1) << x << ", " << y;
  }
  // The outline: across y at x = 3 the shadow ends at y = +-1, and along x at y = 0 at x = 5.
  auto edge = [&](Eigen::Vector2d from, Eigen::Vector2d to) {
    for (int i = 0; i <= 400; ++i) {
      const Eigen::Vector2d p = from + (to - from) * i / 400.0;
      if (at(b, p.x(), p.y()) > (ambient + sunlit) / 2) return p;
    }
    return to;
  };
  EXPECT_NEAR(edge({3, 0}, {3, 3}).y(), 1.0, 0.15);
  EXPECT_NEAR(edge({3, 0}, {3, -3}).y(), -1.0, 0.15);
  EXPECT_NEAR(edge({3, 0}, {8, 0}).x(), 5.0, 0.15);
}

// Clouds 100 m up whose texture is cloud on its left half over a 40 m period: under a light
// travelling (0.3, 0, -1) a ground point x looks toward the sun through the layer at x - 30 m, so
// cloud shades x in [-10, 10) (mod 40) at t = 0, and the wind carries that band 3 m east a second.
// A UAV body (Scene::body_meshes, a 1 m cube here) at each of CameraView::bodies: seen where it
// is, 10 m under a camera 20 m up, and its shadow cast along the light onto the ground, 10 m east
// of it under a sun 45 deg up from the west; with no bodies in the view neither shows.
TEST_P(ShadowTest, AUavBodyIsSeenAndCastsItsShadowWhereTheLightPutsIt) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  Scene s;
  s.materials.push_back(Material{});
  s.static_meshes.push_back(testing::square({0, 0, 0}, 80, {1, 1, 1}, 0));
  s.body_meshes.push_back(box(-0.5, 0.5, -0.5, 0.5, 1));
  s.body_meshes.back().material = 0;
  s.light.direction = {1, 0, -1};
  s.light.shadows = true;
  s.msaa = 1;
  Renderer r(ctx, s);
  const geometry::PinholeCamera cam(250, 250, 199.5, 199.5, 400, 400);  // 8 cm a pixel on the ground
  CameraView view{cam, {geometry::nadir_R_CW(), {5, 0, 20}}};
  const Frame empty = r.render(view);
  view.bodies = {{{0, 0, 9.5}, 0.3}};  // bottom at 9.5 m, top at 10.5 m
  const Frame f = r.render(view);
  auto px = [&](const Eigen::Vector3d& p) {
    const auto uv = cam.project(view.pose.to_camera(p));
    return cv::Point(static_cast<int>(std::lround(uv->x())), static_cast<int>(std::lround(uv->y())));
  };
  auto grey = [](const Frame& fr, cv::Point q) {
    const cv::Vec3b c = fr.rgb.at<cv::Vec3b>(q);
    return (c[0] + c[1] + c[2]) / 3.0;
  };
  // The body: its top 9.5 m from the camera along the optical axis; nothing there without it.
  EXPECT_NEAR(f.depth.at<float>(px({0, 0, 10.5})), 9.5, 0.05);
  EXPECT_NEAR(empty.depth.at<float>(px({0, 0, 10.5})), 20, 0.05);
  // Its shadow: the cube's centre (0, 0, 10) cast along (1, 0, -1) meets the ground at (10, 0).
  const double ambient = 255 * 0.45, sunlit = 255 * (0.45 + 0.65 * std::sqrt(0.5));
  EXPECT_NEAR(grey(f, px({10, 0, 0})), ambient, 2);
  EXPECT_NEAR(grey(empty, px({10, 0, 0})), sunlit, 2);
  for (const auto& q : {Eigen::Vector3d(10, 1.2, 0), Eigen::Vector3d(11.8, 0, 0), Eigen::Vector3d(8.2, 0, 0)})
    EXPECT_NEAR(grey(f, px(q)), sunlit, 2) << q.transpose();
}

TEST_P(ShadowTest, CloudShadowsFallWhereTheSunLooksThroughTheLayerAndDriftWithTheWind) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  Scene s;
  s.materials.push_back(Material{});
  s.static_meshes.push_back(testing::square({0, 0, 0}, 200, {1, 1, 1}, 0));
  s.light.direction = {0.3, 0, -1};
  s.light.ambient = 0.3, s.light.diffuse = 0.5;
  s.light.shadows = true;
  s.light.clouds = {.cover = 0.5, .scale = 5, .height = 100, .wind = {3, 0, 0}, .transmission = 0.35, .softness = 0.1};
  s.clouds = cv::Mat(512, 512, CV_8U, cv::Scalar(0));
  s.clouds(cv::Rect(0, 0, 256, 512)).setTo(255);
  s.msaa = 1;
  const geometry::PinholeCamera cam(500, 500, 199.5, 199.5, 400, 400);  // +-12 m at 30 m
  Renderer r(ctx, s);
  const double direct = 0.5 * 1 / std::sqrt(1 + 0.09);
  const double lit = 255 * (0.3 + direct), shaded = 255 * (0.3 + 0.35 * direct);
  for (const double t : {0.0, 1.0}) {
    const CameraView view{cam, {geometry::nadir_R_CW(), {0, 0, 30}}, t};
    cv::Mat g;
    cv::cvtColor(r.render(view).rgb, g, cv::COLOR_RGB2GRAY);
    auto at = [&](double x) {
      const auto uv = cam.project(view.pose.to_camera({x, 0, 0}));
      return static_cast<double>(g.at<std::uint8_t>(static_cast<int>(std::lround(uv->y())), static_cast<int>(std::lround(uv->x()))));
    };
    for (double x = -11.5; x <= 11.5; x += 1.0) {
      const double u = std::fmod(std::fmod(x - 30 - 3 * t, 40) + 40, 40);  // m into the period
      if (std::abs(u - 20) < 0.3 || u < 0.3 || u > 39.7) continue;        // the edges blur a texel
      EXPECT_NEAR(at(x), u < 20 ? shaded : lit, 3) << "t " << t << ", x " << x;
    }
  }
}

// A rolling shutter's bands, each with the shadow map of its own rows' receivers, against the
// same bands sharing the frame's map (CameraView::shadow_views): one map drawn instead of one a
// band, and the frame within a grey level of the per-band one but on the shadow's edge, where the
// maps' texels differ.
TEST_P(ShadowTest, BandsOfOneFrameShareOneShadowMapAndMatchTheirOwnMaps) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  Scene scene = shadow_scene(true);
  scene.static_meshes.front() = Mesh{};
  for (int i = 0; i < 30; ++i)  // the ground in 2 m cells: bands see different chunks
    for (int j = 0; j < 30; ++j) scene.static_meshes.front().append(testing::square({2.0 * i - 29, 2.0 * j - 29, 0}, 2, {1, 1, 1}, 0));
  scene.static_meshes.front().material = 0;
  const geometry::PinholeCamera cam(250, 250, 199.5, 199.5, 400, 400);
  sim::ShutterSpec s;
  s.type = sim::ShutterSpec::Type::Rolling;
  s.line_delay = 1e-4;
  s.rows_per_band = 50;
  auto pose_at = [](double dt) { return geometry::CameraPose{geometry::nadir_R_CW(), Eigen::Vector3d(2 + 5 * dt, 0, 30)}; };
  Renderer own(ctx, scene), shared(ctx, scene);
  const Frame a = expose(s, 0, cam.width(), cam.height(), [&](double dt, int row0, int rows) {
    return own.render_rows({cam, pose_at(dt)}, std::nullopt, row0, rows);
  });
  const Frame b = expose(s, 0, cam.width(), cam.height(), [&](double dt, int row0, int rows) {
    CameraView v{cam, pose_at(dt)};
    v.shadow_views = {{cam, pose_at(0)}};
    return shared.render_rows(v, std::nullopt, row0, rows);
  });
  EXPECT_EQ(shared.shadow_maps_drawn(), 1);
  EXPECT_GE(own.shadow_maps_drawn(), 4);
  cv::Mat ga, gb, diff;
  cv::cvtColor(a.rgb, ga, cv::COLOR_RGB2GRAY);
  cv::cvtColor(b.rgb, gb, cv::COLOR_RGB2GRAY);
  cv::absdiff(ga, gb, diff);
  const double within = cv::countNonZero(diff <= 1) / static_cast<double>(diff.total());
  const double between = 255 * (0.45 + (0.45 + 0.65 * std::sqrt(0.5))) / 2;  // ambient and sunlit
  const double dark_a = cv::countNonZero(ga < between), dark_b = cv::countNonZero(gb < between);
  std::printf("maps %d against %d; %.4f within a level; shadow %.0f against %.0f px\n", shared.shadow_maps_drawn(),
              own.shadow_maps_drawn(), within, dark_b, dark_a);
  EXPECT_GT(dark_a, 400);  // the box's shadow (4 x 2 m, 550 px) is in view
  EXPECT_GT(within, 0.99);
  EXPECT_NEAR(dark_b / dark_a, 1, 0.02);
}

INSTANTIATE_TEST_SUITE_P(Backends, ShadowTest, ::testing::Values(GlBackend::Egl, GlBackend::OsMesa), backend_name);

}  // namespace
}  // namespace wingman::render
