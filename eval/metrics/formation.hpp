// Closed-loop formation metrics (paper section 7.3, Fig. 14): per phase and UAV, the RMS and the
// largest |lambda - lambda_d| per component [lx, ly, lz, psi] over the phase's steps from
// t_start + settling_time on, for the true formation and for the one the controller saw (its
// estimates and AHRS yaw); and the smallest distance between any two UAVs. Also the
// formation.csv writer and the summary table. Open-loop runs have none (present = false).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "eval/metrics/run_record.hpp"

namespace wingman::eval {

struct FormationError {
  Eigen::Vector4d rms = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector4d max_abs = Eigen::Vector4d::Constant(kNaN);
  int steps = 0;
};

struct FormationPhase {
  int phase = 0;
  double t_from = 0;                       // t_start + settling time
  std::vector<FormationError> truth;       // per RunRecord::formation_uavs
  std::vector<FormationError> controller;  // e as the controller computed it
  double min_inter_uav_distance = kNaN;    // over the whole phase, m
};

struct FormationMetrics {
  bool present = false;
  double settling_time = 0;
  std::vector<FormationPhase> phases;
  std::vector<FormationError> total_truth, total_controller;  // every phase's settled steps
  double min_inter_uav_distance = kNaN;                       // over the whole run, m
  double limited_fraction = kNaN;  // of the UAV commands that a limit clipped
};

FormationMetrics compute_formation_metrics(const RunRecord& run);

// One row per step: k, t, phase, then per UAV the true and estimated lambda, lambda_d, error,
// the surface s, the command and the yaws. Nothing is written for an open-loop run.
void write_formation_csv(const RunRecord& run, const std::filesystem::path& path);

// The formation-error table for stdout, or "" for an open-loop run.
std::string format_formation_summary(const FormationMetrics& m, const RunRecord& run);

}  // namespace wingman::eval
