// The consistency diagnosis (eval/metrics/consistency.hpp): a block whose NEES is a chi^2(3) draw scaled
// by k is inside its band for k = 1 and named over- or underconfident for k = 5 and k = 0.2, with
// what the filter assumed beside what the truth did.
#include <gtest/gtest.h>

#include <random>

#include "eval/metrics/consistency.hpp"
#include "eval/metrics/metrics.hpp"

namespace wingman::eval {
namespace {

RunRecord record_with_scaled_nees(double k, std::uint64_t seed) {
  RunRecord r;
  r.agent_names = {"lead", "uav1"};
  r.phases = {{"config1", 0, 60, "1"}};
  r.assumed.accel_sigma = {0.1, 0.2};
  r.assumed.pixel_sigma = 0.5;
  r.assumed.truth_pixel_sigma = 0.5;
  std::mt19937_64 rng(seed);
  std::chi_squared_distribution<double> chi2(3);
  for (int i = 0; i <= 600; ++i) {
    StepRecord s;
    s.k = i;
    s.t = 0.1 * i;
    s.phase = 0;
    s.agents.resize(2);
    for (auto& a : s.agents) {
      a.v_true = {0.3 * std::sin(0.5 * s.t), 0, 0};  // a = 0.15 cos(0.5 t)
      a.nees_p = chi2(rng);
      a.nees_v = k * chi2(rng);
    }
    s.nees = s.agents[0].nees_p + s.agents[1].nees_p + s.agents[0].nees_v + s.agents[1].nees_v;
    s.nees_dof = 12;
    r.steps.push_back(s);
  }
  return r;
}

TEST(Consistency, Chi2MeanBandNarrowsWithIndependentLooks) {
  const auto one = chi2_mean_band(3, 1), many = chi2_mean_band(3, 100);
  EXPECT_NEAR(one.first, 0.072, 0.03);  // chi2_3 0.5 %: 0.072
  EXPECT_NEAR(one.second, 12.84, 0.4);  // chi2_3 99.5 %: 12.84
  EXPECT_LT(many.second - many.first, one.second - one.first);
  EXPECT_NEAR(many.first, 2.42, 0.03);  // chi2_300 0.5 % / 100
  EXPECT_NEAR(many.second, 3.65, 0.03);  // chi2_300 99.5 % / 100
}

TEST(Consistency, ScaledNeesIsNamedWithWhatTheFilterAssumed) {
  const RunRecord ok = record_with_scaled_nees(1.0, 1);
  const Metrics m_ok = compute_metrics(ok);
  EXPECT_EQ(m_ok.consistency.blocks_checked, 4);
  EXPECT_TRUE(m_ok.consistency.findings.empty());

  const Metrics over = compute_metrics(record_with_scaled_nees(5.0, 2));
  ASSERT_EQ(over.consistency.findings.size(), 2u);  // both agents' velocity
  const ConsistencyFinding& f = over.consistency.findings[1];
  EXPECT_EQ(f.agent, "uav1");
  EXPECT_EQ(f.block, "velocity");
  EXPECT_EQ(f.phase, "config1");
  EXPECT_EQ(f.verdict, "overconfident");
  EXPECT_DOUBLE_EQ(f.assumed_accel_sigma, 0.2);
  // a = 0.15 cos(0.5 t): the worst 5 s window is centred on a peak, mean cos^2 = 1/2 + sin(2.5)/5.
  EXPECT_NEAR(f.truth_accel, 0.15 * std::sqrt(0.5 + std::sin(2.5) / 5), 0.003);
  EXPECT_DOUBLE_EQ(f.assumed_pixel_sigma, 0.5);

  const Metrics under = compute_metrics(record_with_scaled_nees(0.2, 3));
  ASSERT_EQ(under.consistency.findings.size(), 2u);
  EXPECT_EQ(under.consistency.findings[0].verdict, "conservative");
}

}  // namespace
}  // namespace wingman::eval
