// Turns a RunRecord into the paper's tables (docs/design.md, evaluation): per-phase position MSE (Table 4),
// landmark MSE (Table 5), outlier counts (Table 3), NEES, timings and map size. Step k == 0,
// the known initial state, never enters a metric. Undefined values (empty sets) are NaN.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "eval/metrics/formation.hpp"
#include "eval/metrics/consistency.hpp"
#include "eval/metrics/run_record.hpp"

namespace wingman::eval {

// Position error of one agent over a set of steps.
struct AgentError {
  Eigen::Vector3d mse = Eigen::Vector3d::Constant(kNaN);  // per axis, m^2
  double rms_error = kNaN;  // sqrt(mean |p_true - p_est|^2), m
  double max_error = kNaN;  // max |p_true - p_est|, m
  int steps = 0;
};

struct Table4Phase {
  int phase = 0;                    // index into RunRecord::phases
  std::vector<AgentError> agents;   // same order as RunRecord::agent_names
};

struct Table4 {
  std::vector<Table4Phase> phases;  // one per RunRecord::phases entry
  std::vector<AgentError> total;    // over all steps with phase >= 0
};

// Landmark MSE over one set of landmarks. "final" is the estimate at the end of the
// phase for a per-phase row and at the end of the run for the total row.
struct LandmarkMse {
  int count = 0;
  Eigen::Vector3d final_mse = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d init_mse = Eigen::Vector3d::Constant(kNaN);
};

struct Table5 {
  std::vector<LandmarkMse> phases;  // landmarks with init_phase == index
  LandmarkMse total;                // all landmarks, est_final vs truth
};

struct OutlierRow {
  OutlierCounts counts;
  double accepted_outlier_fraction = kNaN;  // outliers_accepted / accepted, NaN if none accepted
};

struct NeesMetrics {
  int dof = 0;
  double mean = kNaN;                  // over steps k > 0, ignoring NaN
  std::vector<double> per_phase_mean;  // one per phase, ignoring NaN
  std::vector<double> per_step;        // aligned with RunRecord::steps (all of them)
  // Per agent (RunRecord::agent_names order), per phase: mean of the position and of the
  // velocity NEES (3 dof each, expected 3 for a consistent filter).
  std::vector<std::vector<double>> position_per_phase, velocity_per_phase;
};

struct Stats {
  double mean = kNaN, median = kNaN, p95 = kNaN, max = kNaN;
  int count = 0;
};

// ms per step, by stage (run_record.hpp, ByStage; the rendered stages 0 in synthetic mode), and
// every stage summed.
struct Timings : ByStage<Stats> {
  Stats total;
};
// Rendered mode: the lead detector against the truth.
struct FrontendMetrics {
  bool present = false;
  double lead_detection_rate = kNaN;  // lead_detected / lead_in_view
  Stats lead_error_px;
  long lead_in_view = 0, lead_detected = 0, lead_false = 0, frames = 0;
  double detect_busy_ms_per_step = kNaN;  // detection's whole duration (timings_ms.detect: exposed part)
  double searched_fraction = kNaN;  // mean share of a frame's pixels the feature detector processed
  Stats accepted_error_px;  // tracked correspondences the filter accepted, to their true projection
  // Of those, how many fall in [0,1), [1,2), [2,3), [3,5), [5,10), [10,inf) px.
  std::vector<long> accepted_error_histogram;
  static constexpr double kErrorBins[] = {1, 2, 3, 5, 10};
};

struct LandmarkCounts {
  std::vector<int> count_per_step;  // aligned with RunRecord::steps
  long initialised = 0;             // RunRecord::landmarks.size()
  int max_in_state = 0;
};

struct Metrics {
  Table4 table4;
  Table5 table5;
  std::vector<OutlierRow> table3;
  NeesMetrics nees;
  Timings timings_ms;
  LandmarkCounts landmarks;
  FormationMetrics formation;  // closed loop only (formation.hpp)
  FrontendMetrics frontend;    // rendered mode only
  Consistency consistency;     // NEES blocks outside their band, and why (consistency.hpp)
};

// Throws std::invalid_argument if a step's agent count differs from agent_names or a step
// names a phase that RunRecord::phases does not have.
Metrics compute_metrics(const RunRecord& run);

// Mean, median, 95th percentile (linear interpolation between order statistics, as numpy's
// default) and max of the finite values; NaN fields and count 0 if there are none.
Stats summarise(std::vector<double> values);

}  // namespace wingman::eval
