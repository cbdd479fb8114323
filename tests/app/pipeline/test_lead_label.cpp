// The lead's ground-truth label (cam0_lead0): the visible share of its silhouette and the box of
// the pixels the frame shows, against geometry: a 2 m square lead seen from 20 m straight above,
// whole, half under a higher roof, half past the image's edge.
#include <gtest/gtest.h>

#include "app/pipeline/lead_label.hpp"
#include "geometry/rotation.hpp"
#include "render/render_test_support.hpp"
#include "render/renderer.hpp"

namespace wingman::app::test {
namespace {

using render::testing::square;

struct Shot {
  geometry::LeadImage label;
  geometry::PinholeCamera cam;
};

// The lead: a 2 m square 0.5 m under x_h, which is at the origin. roof: a 2 m square 3 m up
// centred 1 m along x, over the lead's half x > 0.
Shot shoot(const Eigen::Vector3d& camera_at, bool roof) {
  auto& c = render::testing::context_for(render::GlBackend::Auto);
  if (!c.ctx) return {};
  render::Scene s;
  render::Material unlit;
  unlit.unlit = true;
  s.materials.push_back(unlit);
  s.static_meshes.push_back(square({0, 0, -1}, 400, {0.2, 0.2, 0.2}, 0));
  if (roof) s.static_meshes.push_back(square({1, 0, 3}, 2, {0.5, 0.5, 0.5}, 0));
  s.lead_meshes.push_back(square({0, 0, -0.5}, 2, {1, 1, 1}, 0));
  render::Renderer r(*c.ctx, s);
  const geometry::PinholeCamera cam(500, 500, 319.5, 239.5, 640, 480);
  const render::CameraView view{cam, {geometry::nadir_R_CW(), camera_at}};
  const render::LeadPose lead{};
  const render::Frame f = r.render(view, lead);
  const auto sil = r.lead_silhouette(view, lead);
  return {lead_label(Eigen::Vector3d::Zero(), cam, view.pose, f.depth, sil), cam};
}

TEST(LeadLabel, AWholeLeadIsAllVisibleAndItsBoxIsItsProjection) {
  if (!render::testing::context_for(render::GlBackend::Auto).ctx)
    WINGMAN_NO_GL_CONTEXT(render::testing::context_for(render::GlBackend::Auto).why);
  const Shot s = shoot({0, 0, 20}, false);
  EXPECT_NEAR(s.label.uv.x(), 319.5, 1e-9);
  EXPECT_NEAR(s.label.uv.y(), 239.5, 1e-9);
  EXPECT_NEAR(s.label.distance, 20, 1e-12);
  EXPECT_DOUBLE_EQ(s.label.visible, 1.0);
  // 2 m at 20.5 m: 48.8 px, centred on the principal point (pixel centres inside: 48 or 49 wide).
  EXPECT_NEAR(s.label.box_u1 - s.label.box_u0, 48.8, 1.0);
  EXPECT_NEAR(s.label.box_v1 - s.label.box_v0, 48.8, 1.0);
  EXPECT_NEAR(0.5 * (s.label.box_u0 + s.label.box_u1 - 1), 319.5, 0.6);
  EXPECT_NEAR(0.5 * (s.label.box_v0 + s.label.box_v1 - 1), 239.5, 0.6);
}

TEST(LeadLabel, AHigherRoofOverHalfTheLeadLeavesHalfOfItVisible) {
  if (!render::testing::context_for(render::GlBackend::Auto).ctx)
    WINGMAN_NO_GL_CONTEXT(render::testing::context_for(render::GlBackend::Auto).why);
  // The camera straight above the roof's edge (x = 0): the edge's ray is vertical, so the roof
  // hides exactly the lead's half x > 0; the box keeps the other half, half as wide and as tall.
  const Shot s = shoot({0, 0, 20}, true);
  EXPECT_NEAR(s.label.visible, 0.5, 0.03);
  EXPECT_NEAR(s.label.box_u1 - s.label.box_u0 + s.label.box_v1 - s.label.box_v0, 48.8 * 1.5, 2.0);
}

TEST(LeadLabel, ALeadHalfPastTheImagesEdgeIsHalfVisibleAndItsBoxIsCut) {
  if (!render::testing::context_for(render::GlBackend::Auto).ctx)
    WINGMAN_NO_GL_CONTEXT(render::testing::context_for(render::GlBackend::Auto).why);
  // The lead's centre (20.5 m deep) on the image's left edge, u = -0.5: the camera moved along
  // the image's u axis in the world; x_h, 0.5 m higher, projects 8 px further out.
  const Eigen::Vector3d u_axis_W = geometry::nadir_R_CW().row(0).transpose();
  const Shot s = shoot(Eigen::Vector3d(0, 0, 20) + u_axis_W * (319.5 + 0.5) * 20.5 / 500.0, false);
  EXPECT_NEAR(s.label.uv.x(), -8.5, 1e-6);
  EXPECT_NEAR(s.label.visible, 0.5, 0.03);
  EXPECT_EQ(s.label.box_u0, 0);
  EXPECT_NEAR(s.label.box_u1, 24.4, 1.0);
}

}  // namespace
}  // namespace wingman::app::test
