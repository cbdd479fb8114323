// The closed loop's truth (section 6): UAVs that fly what they are commanded, and Delta_g.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sim/closed_loop_truth.hpp"
#include "sim/scenario.hpp"

namespace wingman::sim {
namespace {

TEST(ClosedLoopTruth, StartsAtTheSpecAndRefusesOtherTimes) {
  const auto s = parse_scenarios("control: {}\n", "a.yaml").front();
  ClosedLoopTruth truth(s);
  EXPECT_EQ(truth.uav(0, 0.0).position, Eigen::Vector3d(-1.5, 0, 15));
  EXPECT_EQ(truth.uav_yaw(1, 0.0), 0.5);
  EXPECT_THROW(truth.uav(0, 0.1), std::logic_error);
  truth.set_uav(0, {1, 2, 3}, {0, 0, 0}, 0.2);
  truth.set_time(0.1);
  EXPECT_EQ(truth.camera(0, 0.1).position, Eigen::Vector3d(1, 2, 3));
}

TEST(InputDisturbance, BoundedAndReproducible) {
  const Eigen::Vector4d bound(0.3, 0.2, 0.1, 0.05);
  const InputDisturbance a(bound, 2, 7), b(bound, 2, 7), c(bound, 2, 8);
  Eigen::Vector4d peak = Eigen::Vector4d::Zero();
  for (int k = 0; k < 5000; ++k) {
    const Eigen::Vector4d d = a(1, k * 0.1);
    EXPECT_TRUE(((d.cwiseAbs() - bound).array() <= 1e-12).all());
    peak = peak.cwiseMax(d.cwiseAbs());
    EXPECT_EQ(d, b(1, k * 0.1));
  }
  EXPECT_TRUE(((peak.array() / bound.array()) > 0.7).all());  // it does use its bound
  EXPECT_NE(a(0, 3.0), c(0, 3.0));
}

}  // namespace
}  // namespace wingman::sim
