// The closed loop in process on a short version of scenes/paper_closed_loop_synthetic.yaml: the
// controller flies the UAVs into the formation of section 7.3 from the estimates, and the record
// holds what the formation metrics need.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "app/pipeline/pipeline.hpp"
#include "eval/metrics/metrics.hpp"
#include "app/config/run_config.hpp"

namespace wingman::app {
namespace {

app::RunConfig short_closed_loop() {
  std::ifstream in(WINGMAN_SOURCE_DIR "/scenes/paper_closed_loop_synthetic.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string y = ss.str();
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto pos = y.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    y.replace(pos, from.size(), to);
  };
  replace("duration: 210", "duration: 45");
  replace("from: 0, to: 70", "from: 0, to: 15");
  replace("from: 70, to: 140", "from: 15, to: 30");
  replace("from: 140, to: 210", "from: 30, to: 45");
    return app::parse_run_configs(y, "short_closed_loop.yaml").front();
}

TEST(ClosedLoop, FliesIntoTheFormation) {
  const app::RunConfig scn = short_closed_loop();
  ASSERT_TRUE(scn.closed_loop());
  const auto rec = run_synthetic(scn);
  ASSERT_TRUE(rec.closed_loop);
  ASSERT_EQ(rec.steps.size(), 451u);
  ASSERT_EQ(rec.formation_uavs.size(), 2u);
  for (const auto& s : rec.steps) ASSERT_EQ(s.formation.size(), 2u);

  // The UAVs start at psi = 1 and 0.5 and away from lambda_d; they end up in formation.
  const auto& f0 = rec.steps.front().formation;
  EXPECT_DOUBLE_EQ(f0[0].yaw_true, 1.0);
  EXPECT_DOUBLE_EQ(f0[1].yaw_true, 0.5);
  EXPECT_GT(std::abs(f0[0].error_true()(1)), 1.0);

  const eval::Metrics m = eval::compute_metrics(rec);
  ASSERT_TRUE(m.formation.present);
  ASSERT_EQ(m.formation.phases.size(), 3u);
  for (const auto& p : m.formation.phases) {
    for (std::size_t u = 0; u < 2; ++u) {
      const auto& e = p.truth[u];
      EXPECT_GE(e.steps, 50);  // the last 5 s of each 15 s phase at 10 Hz
      EXPECT_LE(e.steps, 51);
      std::printf("phase %d uav%zu rms truth %.3f %.3f %.3f %.3f controller %.3f %.3f %.3f %.3f\n",
                  p.phase, u + 1, e.rms(0), e.rms(1), e.rms(2), e.rms(3), p.controller[u].rms(0),
                  p.controller[u].rms(1), p.controller[u].rms(2), p.controller[u].rms(3));
      // The true error adds the estimation error, large this early in configuration 2 (range
      // and GPS only); the 210 s scenario checks the 0.5 m bar after 70 s of mapping.
      for (int i = 0; i < 3; ++i) EXPECT_LT(e.rms(i), 2.0) << "phase " << p.phase << " uav " << u;
      EXPECT_LT(e.rms(3), 0.1) << "phase " << p.phase << " uav " << u;
      // The controller's view of its own error is tighter than the truth's.
      EXPECT_LT(p.controller[u].rms.head<3>().maxCoeff(), 0.5);
    }
  }
  EXPECT_GT(m.formation.min_inter_uav_distance, 1.0);
  // The estimates the controller used stay good: GPS pins the lead in configurations 1 and 2.
  EXPECT_LT(m.table4.phases[0].agents[0].rms_error, 1.5);
  EXPECT_LT(m.table4.phases[1].agents[1].rms_error, 2.5);
}

TEST(ClosedLoop, IsReproducible) {
  const app::RunConfig scn = short_closed_loop();
  const auto a = run_synthetic(scn), b = run_synthetic(scn);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  const auto& fa = a.steps.back().formation[1];
  const auto& fb = b.steps.back().formation[1];
  EXPECT_EQ(fa.position_true, fb.position_true);
  EXPECT_EQ(fa.command, fb.command);
}

}  // namespace
}  // namespace wingman::app
