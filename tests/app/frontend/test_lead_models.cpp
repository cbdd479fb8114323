// The shipped leads other than the truck (scenes/person_lead_rendered.yaml: a walking person;
// scenes/aerial_lead_rendered.yaml: a quadrotor): rendered from both UAVs, the cue on top of each
// model is found by the lead detector at the projection of the lead's reference point x_h, and the
// depth there is x_h's own (the cue is what the camera sees at x_h).
#include <gtest/gtest.h>

#include <memory>

#include "app/config/run_config.hpp"
#include "app/app_test_support.hpp"
#include "gl_required.hpp"
#include "render/gl_context.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "sim/truth.hpp"
#include "vision/lead_detector.hpp"

namespace wingman::app::test {
namespace {

class LeadModelTest : public ::testing::TestWithParam<const char*> {};

TEST_P(LeadModelTest, CueIsDetectedAtTheReferencePointFromEveryUav) {
  std::unique_ptr<render::GlContext> ctx;
  try {
    ctx = render::create_gl_context(render::GlBackend::Auto);
  } catch (const render::GlContextError& e) {
    WINGMAN_NO_GL_CONTEXT(e.what());
  }
  const RunConfig scn = load_run_configs((kSourceDir / "scenes" / GetParam()).string()).front();
  const sim::OpenLoopTruth truth(scn);
  render::Renderer renderer(*ctx, render::build_scene(sim::describe_world(scn)));
  vision::LeadDetector detector;  // the frontend's default: DICT_4X4_50, id 0
  for (double t : {0.0, 11.3, 27.9}) {
    const sim::LeadPose lead = sim::lead_pose(truth, t, scn.world);
    for (int j = 0; j < static_cast<int>(scn.uavs.size()); ++j) {
      SCOPED_TRACE(scn.uavs[j].name + " at t = " + std::to_string(t));
      const geometry::PinholeCamera cam = scn.uavs[j].camera.camera();
      const render::CameraView view{cam, truth.camera_R_CW(j, t), truth.camera(j, t).position};
      const render::Frame f = renderer.render(view, lead);
      const Eigen::Vector3d p_C = view.pose.R_CW * (lead.position - view.pose.position);
      const auto uv = cam.project(p_C);
      ASSERT_TRUE(uv && cam.in_image(*uv, 30)) << "x_h out of view";
      const auto d = detector.detect(f.gray());
      ASSERT_TRUE(d.has_value()) << "cue not detected";
      EXPECT_LT((d->uv - *uv).norm(), 1.5) << "detected at " << d->uv.transpose() << ", x_h at "
                                            << uv->transpose();
      EXPECT_GT(d->size_px, 20);
      const float depth = f.depth.at<float>(static_cast<int>(std::lround((*uv)(1))),
                                            static_cast<int>(std::lround((*uv)(0))));
      EXPECT_NEAR(depth, p_C.z(), 0.02);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Leads, LeadModelTest,
                         ::testing::Values("person_lead_rendered.yaml", "aerial_lead_rendered.yaml"),
                         [](const auto& info) {
                           return std::string(info.index == 0 ? "Person" : "Quadrotor");
                         });

}  // namespace
}  // namespace wingman::app::test
