// A hand-built RunRecord with known errors, and a self-removing temporary directory.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "eval/metrics/run_record.hpp"
#include "io/io_test_support.hpp"

namespace wingman::eval::test {

// Two phases ("config1" t in [0,10), "config2" [10,20]), agents lead and uav1, steps k = 0..21
// at t = k. Errors p_est - p_true: k == 0 huge (must be skipped); lead (0.5,0,0) throughout;
// uav1 (0,1,0) in phase 0 (k = 1..9) and (0,0,2) in phase 1 (k = 10..20); k == 21 is outside
// every phase (phase -1) with a huge error. NEES = k except NaN at k = 5, dof 12.
// Block NEES: position 1 (lead) and 2 (uav1); velocity 2 (lead) and k/2 (uav1, NaN at k = 5).
// t_predict_ms = k, t_update_ms = 2k, t_init_ms = 0.
// Landmarks: two initialised in phase 0 (one removed), none in phase 1, one with phase -1.
inline RunRecord make_record() {
  RunRecord r;
  r.scenario_path = "scenes/test.yaml";
  r.scenario_name = "test";
  r.variant = "default";
  r.estimator_mode = "multi";
  r.seed = 42;
  r.software_version = "0.1.0+test";
  r.agent_names = {"lead", "uav1"};
  r.phases = {{"config1", 0.0, 10.0, "1"}, {"config2", 10.0, 20.0, "2"}};
  r.wall_time_s = 1.5;
  for (int k = 0; k <= 21; ++k) {
    StepRecord s;
    s.k = k;
    s.t = k;
    s.phase = k == 21 ? -1 : (k < 10 ? 0 : 1);
    for (int a = 0; a < 2; ++a) {
      AgentStep as;
      as.p_true = Eigen::Vector3d(10.0 * a + 0.1 * k, -2.0 + 0.05 * k, 15.0 + a);
      as.v_true = Eigen::Vector3d(0.1, 0.05, 0);
      as.v_est = as.v_true + Eigen::Vector3d(0.01, 0, 0);
      as.p_sigma = Eigen::Vector3d(0.3, 0.4, 0.5 + 0.01 * k);
      Eigen::Vector3d e;
      if (k == 0 || k == 21) {
        e = Eigen::Vector3d(100, 100, 100);
      } else if (a == 0) {
        e = Eigen::Vector3d(0.5, 0, 0);
      } else {
        e = s.phase == 0 ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(0, 0, 2);
      }
      as.p_est = as.p_true + e;
      as.nees_p = 1.0 + a;
      as.nees_v = a == 0 ? 2.0 : (k == 5 ? kNaN : 0.5 * k);
      s.agents.push_back(as);
    }
    s.nees = k == 5 ? kNaN : k;
    s.nees_dof = 12;
    s.landmarks = k < 3 ? k : 3;
    s.counts.landmarks_visible = 2;
    s.counts.matches_offered = 5;
    s.counts.matches_accepted = 4;
    s.counts.initialised = k == 1 ? 1 : 0;
    s.t_ms.predict = k;
    s.t_ms.update = 2.0 * k;
    s.t_ms.init = 0;
    r.steps.push_back(s);
  }
  auto lm = [](std::int64_t id, int phase, Eigen::Vector3d truth, Eigen::Vector3d init_err,
               Eigen::Vector3d end_err, Eigen::Vector3d final_err, double t_removed,
               std::string origin) {
    LandmarkRecord l;
    l.id = id;
    l.truth = truth;
    l.init_phase = phase;
    l.t_init = phase >= 0 ? 1.0 + id : 21.0;
    l.est_init = truth + init_err;
    l.est_phase_end = truth + end_err;
    l.est_final = truth + final_err;
    l.t_removed = t_removed;
    l.origin = std::move(origin);
    return l;
  };
  r.landmarks.push_back(lm(1, 0, {1, 2, 0}, {1, 0, 0}, {0.5, 0, 0}, {0.1, 0, 0}, kNaN,
                           "cooperative"));
  r.landmarks.push_back(lm(2, 0, {3, 4, 0}, {3, 0, 2}, {0.5, 1, 0}, {0.3, 0, 0}, 15.0,
                           "inverse_depth"));
  r.landmarks.push_back(lm(3, -1, {5, 6, 0.5}, {0, 0, 4}, {0, 0, 1}, {0, 0, 1}, kNaN,
                           "inverse_depth"));
  r.outliers = {{"uav1", 1000, 100, 120, 800, 8}, {"cooperative", 50, 0, 5, 0, 0}};
  return r;
}

using io::test::TempDir;

}  // namespace wingman::eval::test
