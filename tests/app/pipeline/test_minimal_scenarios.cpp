// A user's first scenario: only `uavs:` and `phases:` (configurations 1, 2, 3), everything else at
// its documented default. The defaults must give a consistent filter for any team size: the
// average NEES within [0.3, 2] x its dimension and every agent's position error under 1 m RMS in
// every phase (the square root of Table 4's per-phase MSE), on 5 seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "app/pipeline/pipeline.hpp"
#include "app/config/run_config.hpp"

namespace wingman::app {
namespace {

std::string minimal_scenario(int uavs) {
  const char* positions[] = {"[-1.5, 0, 15]", "[1.5, 0, 17]", "[0, -3, 16]", "[0, 3, 18]"};
  std::string y = "duration: 60\nuavs:\n";
  for (int i = 0; i < uavs; ++i)
    y += "  - {name: q" + std::to_string(i + 1) + ", initial_position: " + positions[i] + "}\n";
  return y +
         "phases:\n"
         "  - {from: 0, to: 20, config: 1}\n"
         "  - {from: 20, to: 40, config: 2}\n"
         "  - {from: 40, to: 60, config: 3}\n";
}

class MinimalScenario : public ::testing::TestWithParam<int> {};

TEST_P(MinimalScenario, DefaultsGiveAConsistentFilterOverFiveSeeds) {
  const int n = GetParam();
  RunConfig cfg = parse_run_configs(minimal_scenario(n), "minimal.yaml").front();
  EXPECT_EQ(cfg.single_uav(), n == 1);  // one UAV runs the single-UAV estimator untold
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    cfg.seed = seed;
    const eval::RunRecord rec = run_synthetic(cfg);
    double nees = 0;
    int count = 0, dof = 0;
    // Per phase and agent: sum of squared position errors and the number of steps.
    std::vector<std::vector<double>> sq(3, std::vector<double>(n + 1, 0.0));
    std::vector<int> steps(3, 0);
    for (const auto& st : rec.steps) {
      if (std::isfinite(st.nees)) nees += st.nees, ++count, dof = st.nees_dof;
      if (st.phase < 0) continue;
      ++steps[st.phase];
      for (int a = 0; a <= n; ++a) sq[st.phase][a] += (st.agents[a].p_est - st.agents[a].p_true).squaredNorm();
    }
    ASSERT_GT(count, 0);
    const double mean = nees / count;
    EXPECT_GE(mean, 0.3 * dof) << n << " UAVs, seed " << seed;
    EXPECT_LE(mean, 2.0 * dof) << n << " UAVs, seed " << seed;
    for (int p = 0; p < 3; ++p)
      for (int a = 0; a <= n; ++a)
        EXPECT_LT(std::sqrt(sq[p][a] / steps[p]), 1.0)
            << n << " UAVs, seed " << seed << ", configuration " << p + 1 << ", agent " << rec.agent_names[a];
  }
}

INSTANTIATE_TEST_SUITE_P(TeamsOfOneToFour, MinimalScenario, ::testing::Values(1, 2, 3, 4));

}  // namespace
}  // namespace wingman::app
