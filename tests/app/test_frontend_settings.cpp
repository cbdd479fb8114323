// The scenario's `frontend:` section reaches the vision frontend: every detector the scenario
// accepts maps onto vision's, and each value lands in the right setting.
#include <gtest/gtest.h>

#include "app/rendered_frontend.hpp"
#include "sim/scenario.hpp"

namespace wingman::app {
namespace {

TEST(FrontendSettings, EveryScenarioDetectorMapsOntoVision) {
  for (const char* name : {"orb", "akaze", "sift", "gftt_orb"}) {
    const auto scn = sim::parse_scenarios(std::string("frontend: {detector: ") + name + "}\n", "scn.yaml");
    EXPECT_EQ(vision::to_string(feature_settings(scn.front().frontend).kind), name);
  }
}

TEST(FrontendSettings, ValuesLandInVisionSettings) {
  const auto scn = sim::parse_scenarios(
      "frontend:\n"
      "  max_features: 300\n"
      "  grid: [4, 3]\n"
      "  orb: {fast_threshold: 9, levels: 2, scale_factor: 1.5}\n"
      "  tracking: {gate_d2: 6, ratio: 0.6, max_search_radius_px: 40, max_distance: 45,\n"
      "             match_latest_descriptor: true}\n"
      "  cross_matching: {ratio: 0.65, max_epipolar_px: 2.5, max_reprojection_px: 1.5}\n",
      "scn.yaml");
  const sim::FrontendSpec& spec = scn.front().frontend;
  const vision::FeatureSettings f = feature_settings(spec);
  EXPECT_EQ(f.max_features, 300);
  EXPECT_EQ(f.grid_cols, 4);
  EXPECT_EQ(f.grid_rows, 3);
  EXPECT_EQ(f.orb_fast_threshold, 9);
  EXPECT_EQ(f.orb_levels, 2);
  EXPECT_FLOAT_EQ(f.orb_scale_factor, 1.5f);
  const vision::TrackingSettings t = tracking_settings(spec);
  EXPECT_DOUBLE_EQ(t.gate_d2, 6);
  EXPECT_DOUBLE_EQ(t.ratio, 0.6);
  EXPECT_DOUBLE_EQ(t.max_search_radius_px, 40);
  EXPECT_DOUBLE_EQ(t.max_distance, 45);
  EXPECT_TRUE(t.match_latest_descriptor);
  EXPECT_FALSE(tracking_settings(sim::FrontendSpec{}).match_latest_descriptor);
  const vision::CrossMatchSettings c = cross_match_settings(spec, scn.front().estimator);
  EXPECT_DOUBLE_EQ(c.ratio, 0.65);
  EXPECT_DOUBLE_EQ(c.max_epipolar_px, 2.5);
  EXPECT_DOUBLE_EQ(c.max_reprojection_px, 1.5);
}

// Pairs under the estimator's minimum parallax are dropped by the matcher unless the estimator
// turns them into inverse-depth landmarks, in which case they must reach it.
TEST(FrontendSettings, CrossMatcherParallaxFollowsTheEstimator) {
  const auto off = sim::parse_scenarios("estimator: {initialisation: {min_parallax_deg: 8}}\n", "scn.yaml");
  EXPECT_DOUBLE_EQ(cross_match_settings(off.front().frontend, off.front().estimator).min_parallax_deg, 8);
  const auto on = sim::parse_scenarios(
      "estimator: {initialisation: {min_parallax_deg: 8, low_parallax_inverse_depth: true}}\n", "scn.yaml");
  EXPECT_DOUBLE_EQ(cross_match_settings(on.front().frontend, on.front().estimator).min_parallax_deg, 0);
}

}  // namespace
}  // namespace wingman::app
