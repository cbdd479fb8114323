// The cross matcher's settings of a run: the frontend section's, composed with the estimator's
// initialisation.
#include <gtest/gtest.h>

#include "app/frontend/vision_frontend.hpp"
#include "app/config/run_config.hpp"

namespace wingman::app {
namespace {

// Pairs under the estimator's minimum parallax are dropped by the matcher unless the estimator
// turns them into inverse-depth landmarks, in which case they must reach it.
TEST(FrontendSettings, CrossMatcherParallaxFollowsTheEstimator) {
  const auto off = parse_run_configs(
      "estimator: {initialisation: {min_parallax_deg: 8, low_parallax_inverse_depth: false}}\n"
      "frontend: {cross_matching: {ratio: 0.65}}\n",
      "scn.yaml");
  const vision::CrossMatchSettings c = cross_match_settings(off.front());
  EXPECT_DOUBLE_EQ(c.min_parallax_deg, 8);
  EXPECT_DOUBLE_EQ(c.ratio, 0.65);
  const auto on = parse_run_configs(
      "estimator: {initialisation: {min_parallax_deg: 8, low_parallax_inverse_depth: true}}\n", "scn.yaml");
  EXPECT_DOUBLE_EQ(cross_match_settings(on.front()).min_parallax_deg, 0);
}

}  // namespace
}  // namespace wingman::app
