// A rolling shutter rendered with both backends: each row is drawn from its own pose, so a ground
// target lands within 0.1 px of its true correspondence projected with its row's pose (the pose
// the labels use; this rasteriser draws a still target within about 0.07 px of its projection),
// while the global-shutter projection misses it by pixels.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <vector>

#include <Eigen/Geometry>

#include "geometry/frame_poses.hpp"
#include "geometry/rotation.hpp"
#include "render/renderer.hpp"
#include "render/shutter.hpp"
#include "render_test_support.hpp"

namespace wingman::render {
namespace {

using testing::backend_name;

class RollingShutterTest : public ::testing::TestWithParam<GlBackend> {};

TEST_P(RollingShutterTest, TargetsLandOnTheirRowsPoseProjection) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const geometry::PinholeCamera cam(210.3, 190.7, 161.3, 118.6, 320, 240);
  sim::ShutterSpec s;
  s.type = sim::ShutterSpec::Type::Rolling;
  s.line_delay = 1e-4;  // 24 ms of readout
  const Eigen::Vector3d p0(0.37, -0.21, 20), v(40, -15, 0);  // m, m/s: some 6 px of skew over the frame
  auto pose_at = [&](double dt) { return geometry::CameraPose{geometry::nadir_R_CW(), p0 + v * dt}; };
  std::vector<Eigen::Vector3d> targets;
  for (double x : {-8.0, 0.0, 8.0})
    for (double y : {-7.0, 0.0, 7.0}) targets.push_back({x, y, 0.01});
  Renderer r(ctx, testing::target_scene(targets, 1.5, 0.5));
  const Frame f = expose(s, 0, cam.width(), cam.height(), [&](double dt, int row0, int rows) {
    return r.render_rows({cam, pose_at(dt)}, std::nullopt, row0, rows);
  });
  std::vector<geometry::CameraPose> rows;
  for (int row = 0; row < cam.height(); ++row) rows.push_back(pose_at(row_time(s, row, cam.height())));
  const geometry::FramePoses poses(pose_at(0), rows);
  cv::Mat gray;
  cv::cvtColor(f.rgb, gray, cv::COLOR_RGB2GRAY);
  double worst_global = 0;
  for (const auto& p : targets) {
    const auto uv = cam.project(poses.to_camera(cam, p));
    const auto global = cam.project(pose_at(0).to_camera(p));
    ASSERT_TRUE(uv && global);
    const Eigen::Vector2d got = testing::centroid(gray, *uv, 14);
    EXPECT_LT((got - *uv).norm(), 0.1) << "predicted " << uv->transpose() << " rendered " << got.transpose()
                                       << " on " << ctx.description();
    worst_global = std::max(worst_global, (got - *global).norm());
  }
  EXPECT_GT(worst_global, 2.5);  // the effect is there (3.1 px here)
}

TEST_P(RollingShutterTest, ABandOfRowsIsThoseRowsOfTheWholeFrame) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const geometry::PinholeCamera cam(210.3, 190.7, 161.3, 118.6, 320, 240);
  const CameraView view{cam, {geometry::nadir_R_CW(), {0.37, -0.21, 20}}};
  Renderer r(ctx, testing::target_scene({{0, 0, 0.01}, {3, 2, 0.01}, {-4, -3, 0.01}}, 0.6));
  const Frame whole = r.render(view);
  for (int row0 : {0, 57, 118, 200}) {
    const Frame band = r.render_rows(view, std::nullopt, row0, 40);
    EXPECT_LE(cv::norm(band.rgb, whole.rgb.rowRange(row0, row0 + 40), cv::NORM_INF), 1) << "rows from " << row0;
    EXPECT_LE(cv::norm(band.depth, whole.depth.rowRange(row0, row0 + 40), cv::NORM_INF), 1e-3);
  }
}

// The one-pass draw (CameraView::rows: every vertex from its own row's pose) against the exact
// per-row render (a band of one row per row), for a camera translating at 43 m/s and turning at
// 3 rad/s about its axis over a 24 ms readout, pinhole and with barrel distortion.
TEST_P(RollingShutterTest, OnePassLandsTargetsWhereThePerRowRenderDoes) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  geometry::Distortion barrel;
  barrel.k1 = -0.2, barrel.k2 = 0.05, barrel.p1 = 1e-3;
  for (const geometry::Distortion& d : {geometry::Distortion{}, barrel}) {
    const geometry::PinholeCamera cam(210.3, 190.7, 161.3, 118.6, 320, 240, d);
    sim::ShutterSpec s;
    s.type = sim::ShutterSpec::Type::Rolling;
    s.line_delay = 1e-4;
    s.rows_per_band = 1;
    const Eigen::Vector3d p0(0.37, -0.21, 20), v(40, -15, 0);
    auto pose_at = [&](double dt) {
      return geometry::CameraPose{Eigen::AngleAxisd(3 * dt, Eigen::Vector3d::UnitZ()) * geometry::nadir_R_CW(),
                                  p0 + v * dt};
    };
    std::vector<Eigen::Vector3d> targets;
    for (double x : {-7.0, 0.0, 7.0})
      for (double y : {-6.0, 0.0, 6.0}) targets.push_back({x, y, 0.01});
    // Targets of two triangles 1.5 m (16 px) across: the rotation over the readout bends their
    // edges by far less than the rasteriser's own error.
    Renderer r(ctx, testing::target_scene(targets, 1.5, 0.5));
    const Frame per_row = expose(s, 0, cam.width(), cam.height(), [&](double dt, int row0, int rows) {
      return r.render_rows({cam, pose_at(dt)}, std::nullopt, row0, rows);
    });
    CameraView view{cam, pose_at(0)};
    const int n = 16;
    for (int i = 0; i < n; ++i) view.rows.push_back({pose_at(row_time(s, (cam.height() - 1.0) * i / (n - 1), cam.height()))});
    const Frame one_pass = r.render(view);
    const Frame global = r.render({cam, pose_at(0)});
    cv::Mat g_row, g_one, g_global;
    cv::cvtColor(per_row.rgb, g_row, cv::COLOR_RGB2GRAY);
    cv::cvtColor(one_pass.rgb, g_one, cv::COLOR_RGB2GRAY);
    cv::cvtColor(global.rgb, g_global, cv::COLOR_RGB2GRAY);
    double worst = 0, worst_global = 0;
    int found = 0;
    for (const auto& p : targets) {
      const auto at = cam.project(pose_at(0).to_camera(p));
      ASSERT_TRUE(at);
      if (at->x() < 12 || at->y() < 12 || at->x() > cam.width() - 13 || at->y() > cam.height() - 13) continue;
      const Eigen::Vector2d a = testing::centroid(g_row, *at, 14), b = testing::centroid(g_one, *at, 14);
      worst = std::max(worst, (a - b).norm());
      worst_global = std::max(worst_global, (a - testing::centroid(g_global, *at, 14)).norm());
      const cv::Point c(static_cast<int>(std::lround(a.x())), static_cast<int>(std::lround(a.y())));
      EXPECT_NEAR(one_pass.depth.at<float>(c), per_row.depth.at<float>(c), 2e-3);
      ++found;
    }
    EXPECT_GE(found, 7);
    EXPECT_LT(worst, 0.05) << "k1 " << d.k1 << " on " << ctx.description();  // 0.026 px here
    EXPECT_GT(worst_global, 1.0);  // the shutter's effect is there to be matched
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, RollingShutterTest, ::testing::Values(GlBackend::Egl, GlBackend::OsMesa),
                         backend_name);

}  // namespace
}  // namespace wingman::render
