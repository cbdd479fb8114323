#include <gtest/gtest.h>

#include <cmath>

#include "eval/metrics/metrics.hpp"
#include "eval/eval_test_support.hpp"

namespace wingman::eval {
namespace {

TEST(Metrics, Table4PerPhaseMseSkipsInitialStateAndOutsidePhases) {
  const Metrics m = compute_metrics(test::make_record());
  ASSERT_EQ(m.table4.phases.size(), 2u);
  ASSERT_EQ(m.table4.phases[0].agents.size(), 2u);

  // lead: constant 0.5 m in x -> MSE 0.25 in x, 0 in y and z, in every phase and in total.
  for (const Table4Phase& p : m.table4.phases) {
    EXPECT_NEAR(p.agents[0].mse.x(), 0.25, 1e-12);
    EXPECT_NEAR(p.agents[0].mse.y(), 0.0, 1e-12);
    EXPECT_NEAR(p.agents[0].mse.z(), 0.0, 1e-12);
    EXPECT_NEAR(p.agents[0].rms_error, 0.5, 1e-12);
    EXPECT_NEAR(p.agents[0].max_error, 0.5, 1e-12);
  }
  EXPECT_NEAR(m.table4.total[0].mse.x(), 0.25, 1e-12);

  // k == 0 skipped: phase 0 holds k = 1..9.
  EXPECT_EQ(m.table4.phases[0].agents[1].steps, 9);
  EXPECT_EQ(m.table4.phases[1].agents[1].steps, 11);
  EXPECT_EQ(m.table4.total[1].steps, 20);  // k == 21 has phase -1

  const AgentError& u0 = m.table4.phases[0].agents[1];
  EXPECT_NEAR(u0.mse.x(), 0.0, 1e-12);
  EXPECT_NEAR(u0.mse.y(), 1.0, 1e-12);
  EXPECT_NEAR(u0.mse.z(), 0.0, 1e-12);
  EXPECT_NEAR(u0.max_error, 1.0, 1e-12);
  const AgentError& u1 = m.table4.phases[1].agents[1];
  EXPECT_NEAR(u1.mse.y(), 0.0, 1e-12);
  EXPECT_NEAR(u1.mse.z(), 4.0, 1e-12);
  EXPECT_NEAR(u1.rms_error, 2.0, 1e-12);
  EXPECT_NEAR(u1.max_error, 2.0, 1e-12);

  const AgentError& ut = m.table4.total[1];
  EXPECT_NEAR(ut.mse.y(), 9.0 / 20.0, 1e-12);
  EXPECT_NEAR(ut.mse.z(), 4.0 * 11.0 / 20.0, 1e-12);
  EXPECT_NEAR(ut.rms_error, std::sqrt((9.0 * 1 + 11.0 * 4) / 20.0), 1e-12);
  EXPECT_NEAR(ut.max_error, 2.0, 1e-12);
}

TEST(Metrics, Table4EmptyPhaseIsNaN) {
  RunRecord r = test::make_record();
  r.phases.push_back({"config3", 20, 30, "3"});
  const Metrics m = compute_metrics(r);
  ASSERT_EQ(m.table4.phases.size(), 3u);
  EXPECT_EQ(m.table4.phases[2].agents[0].steps, 0);
  EXPECT_TRUE(std::isnan(m.table4.phases[2].agents[0].mse.x()));
  EXPECT_TRUE(std::isnan(m.table4.phases[2].agents[0].max_error));
  EXPECT_TRUE(std::isnan(m.nees.per_phase_mean[2]));
}

TEST(Metrics, Table5PerPhaseAndTotal) {
  const Metrics m = compute_metrics(test::make_record());
  ASSERT_EQ(m.table5.phases.size(), 2u);
  const LandmarkMse& p0 = m.table5.phases[0];
  EXPECT_EQ(p0.count, 2);
  // Phase-end errors (0.5,0,0) and (0.5,1,0); init errors (1,0,0) and (3,0,2).
  EXPECT_NEAR(p0.final_mse.x(), 0.25, 1e-12);
  EXPECT_NEAR(p0.final_mse.y(), 0.5, 1e-12);
  EXPECT_NEAR(p0.final_mse.z(), 0.0, 1e-12);
  EXPECT_NEAR(p0.init_mse.x(), 5.0, 1e-12);
  EXPECT_NEAR(p0.init_mse.y(), 0.0, 1e-12);
  EXPECT_NEAR(p0.init_mse.z(), 2.0, 1e-12);

  const LandmarkMse& p1 = m.table5.phases[1];
  EXPECT_EQ(p1.count, 0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(std::isnan(p1.final_mse[i]));
    EXPECT_TRUE(std::isnan(p1.init_mse[i]));
  }

  // Total: all three landmarks, final errors (0.1,0,0), (0.3,0,0), (0,0,1).
  const LandmarkMse& t = m.table5.total;
  EXPECT_EQ(t.count, 3);
  EXPECT_NEAR(t.final_mse.x(), (0.01 + 0.09) / 3.0, 1e-12);
  EXPECT_NEAR(t.final_mse.z(), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(t.init_mse.x(), 10.0 / 3.0, 1e-12);
  EXPECT_NEAR(t.init_mse.z(), 20.0 / 3.0, 1e-12);
}

TEST(Metrics, Table5EmptyRunIsNaN) {
  RunRecord r = test::make_record();
  r.landmarks.clear();
  const Metrics m = compute_metrics(r);
  EXPECT_EQ(m.table5.total.count, 0);
  EXPECT_TRUE(std::isnan(m.table5.total.final_mse.x()));
  EXPECT_EQ(m.landmarks.initialised, 0);
}

TEST(Metrics, Table3AcceptedOutlierFraction) {
  const Metrics m = compute_metrics(test::make_record());
  ASSERT_EQ(m.table3.size(), 2u);
  EXPECT_EQ(m.table3[0].counts.channel, "uav1");
  EXPECT_EQ(m.table3[0].counts.injected, 100);
  EXPECT_NEAR(m.table3[0].accepted_outlier_fraction, 0.01, 1e-12);
  EXPECT_TRUE(std::isnan(m.table3[1].accepted_outlier_fraction));  // nothing accepted
}

TEST(Metrics, NeesMeanIgnoresNaNAndInitialStep) {
  const Metrics m = compute_metrics(test::make_record());
  EXPECT_EQ(m.nees.dof, 12);
  ASSERT_EQ(m.nees.per_step.size(), 22u);
  EXPECT_TRUE(std::isnan(m.nees.per_step[5]));
  // Run: k = 1..21 without 5 -> (231 - 5) / 20.
  EXPECT_NEAR(m.nees.mean, (231.0 - 5.0) / 20.0, 1e-12);
  // Phase 0: k = 1..9 without 5 -> 40 / 8; phase 1: k = 10..20 -> 15.
  ASSERT_EQ(m.nees.per_phase_mean.size(), 2u);
  EXPECT_NEAR(m.nees.per_phase_mean[0], 40.0 / 8.0, 1e-12);
  EXPECT_NEAR(m.nees.per_phase_mean[1], 15.0, 1e-12);
}

TEST(Metrics, BlockNeesPerAgentAndPhase) {
  const Metrics m = compute_metrics(test::make_record());
  ASSERT_EQ(m.nees.position_per_phase.size(), 2u);  // lead, uav1
  ASSERT_EQ(m.nees.velocity_per_phase.size(), 2u);
  EXPECT_DOUBLE_EQ(m.nees.position_per_phase[0][0], 1.0);
  EXPECT_DOUBLE_EQ(m.nees.position_per_phase[1][1], 2.0);
  EXPECT_DOUBLE_EQ(m.nees.velocity_per_phase[0][1], 2.0);
  // uav1 velocity: phase 0 k = 1..9 without 5 -> 40 / 8 / 2; phase 1 k = 10..20 -> 15 / 2.
  EXPECT_NEAR(m.nees.velocity_per_phase[1][0], 2.5, 1e-12);
  EXPECT_NEAR(m.nees.velocity_per_phase[1][1], 7.5, 1e-12);
}

TEST(Metrics, FrontendAcceptedErrorHistogram) {
  RunRecord r = test::make_record();
  r.frontend.enabled = true;
  r.frontend.accepted_error_px = {0.5, 1.5, 2.5, 4, 7, 20, kNaN, 0.2};
  const Metrics m = compute_metrics(r);
  ASSERT_TRUE(m.frontend.present);
  // Bins [0,1) [1,2) [2,3) [3,5) [5,10) [10,inf); the NaN (no truth) is in none.
  EXPECT_EQ(m.frontend.accepted_error_histogram, (std::vector<long>{2, 1, 1, 1, 1, 1}));
  EXPECT_EQ(m.frontend.accepted_error_px.count, 7);
  EXPECT_DOUBLE_EQ(m.frontend.accepted_error_px.max, 20);
}

TEST(Metrics, SummariseMedianAndP95) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // unsorted on purpose
  v.push_back(kNaN);
  const Stats s = summarise(v);
  EXPECT_EQ(s.count, 100);
  EXPECT_NEAR(s.mean, 50.5, 1e-12);
  EXPECT_NEAR(s.median, 50.5, 1e-12);
  EXPECT_NEAR(s.p95, 95.05, 1e-12);  // 1 + 0.95 * 99
  EXPECT_NEAR(s.max, 100.0, 1e-12);

  const Stats odd = summarise({3.0, 1.0, 2.0});
  EXPECT_NEAR(odd.median, 2.0, 1e-12);
  EXPECT_NEAR(odd.p95, 2.9, 1e-12);

  const Stats none = summarise({});
  EXPECT_EQ(none.count, 0);
  EXPECT_TRUE(std::isnan(none.median));
}

TEST(Metrics, TimingsSkipInitialStep) {
  const Metrics m = compute_metrics(test::make_record());
  // Steps k = 1..21: predict = k, update = 2k, total = 3k.
  EXPECT_EQ(m.timings_ms.predict.count, 21);
  EXPECT_NEAR(m.timings_ms.predict.mean, 11.0, 1e-12);
  EXPECT_NEAR(m.timings_ms.predict.median, 11.0, 1e-12);
  EXPECT_NEAR(m.timings_ms.predict.p95, 20.0, 1e-12);  // 1 + 0.95 * 20
  EXPECT_NEAR(m.timings_ms.update.max, 42.0, 1e-12);
  EXPECT_NEAR(m.timings_ms.total.median, 33.0, 1e-12);
  EXPECT_NEAR(m.timings_ms.init.max, 0.0, 1e-12);
}

TEST(Metrics, LandmarkCounts) {
  const Metrics m = compute_metrics(test::make_record());
  ASSERT_EQ(m.landmarks.count_per_step.size(), 22u);
  EXPECT_EQ(m.landmarks.count_per_step[0], 0);
  EXPECT_EQ(m.landmarks.count_per_step[2], 2);
  EXPECT_EQ(m.landmarks.max_in_state, 3);
  EXPECT_EQ(m.landmarks.initialised, 3);
}

TEST(Metrics, RejectsInconsistentRecord) {
  RunRecord r = test::make_record();
  r.steps[3].agents.pop_back();
  EXPECT_THROW(compute_metrics(r), std::invalid_argument);
  r = test::make_record();
  r.steps[3].phase = 7;
  EXPECT_THROW(compute_metrics(r), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::eval
