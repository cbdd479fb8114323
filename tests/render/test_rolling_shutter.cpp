// A rolling shutter rendered with both backends: each row is drawn from its own pose, so a ground
// target lands within 0.1 px of its true correspondence projected with its row's pose (the pose
// the labels use; this rasteriser draws a still target within about 0.07 px of its projection),
// while the global-shutter projection misses it by pixels.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <vector>

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

INSTANTIATE_TEST_SUITE_P(Backends, RollingShutterTest, ::testing::Values(GlBackend::Egl, GlBackend::OsMesa),
                         backend_name);

}  // namespace
}  // namespace wingman::render
