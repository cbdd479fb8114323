// Why a run's NEES leaves its band: per phase and agent, the position and the velocity NEES
// (3 dof each) against the 99 % chi^2 band of a mean over the phase's steps, counted in independent
// looks (the series' own integrated autocorrelation, eval/metrics/nees_null.hpp); and, for a block outside
// it, what the filter assumed against what happened: its white acceleration against the truth's
// accelerations in that phase, its pixel sigma against the accepted correspondences' error.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "eval/metrics/run_record.hpp"

namespace wingman::eval {

struct Metrics;

// Per axis, the RMS of `a` over each window of `window` samples; the largest over windows and
// axes. The estimator's derived process noise and this diagnosis measure accelerations alike.
double windowed_rms_bound(const std::vector<Eigen::Vector3d>& a, int window);
inline constexpr double kAccelerationWindowS = 5.0;

// The two-sided 99 % band of the mean of n_eff independent chi^2(dof) draws:
// a run checks one block per agent, phase and position|velocity (36 for five UAVs and three
// phases), so a 95 % band would name about two consistent blocks in every such run.
std::pair<double, double> chi2_mean_band(int dof, double n_eff);

struct ConsistencyFinding {
  std::string phase, agent, block;  // block: "position" or "velocity"
  double nees = kNaN, band_lo = kNaN, band_hi = kNaN;  // 3 dof: a consistent block averages 3
  double independent_looks = kNaN;
  std::string verdict;              // "overconfident" (above) or "conservative" (below)
  double assumed_accel_sigma = kNaN;  // m/s^2: the agent's common and own white acceleration
  double truth_accel = kNaN;          // m/s^2: the truth's worst windowed RMS per axis in the phase
  double assumed_pixel_sigma = kNaN;  // px per axis
  double pixel_error = kNaN;          // px per axis: rendered, the accepted correspondences' RMS
                                      // per axis over the run; synthetic, the truth's noise sigma
};

struct Consistency {
  int blocks_checked = 0;
  std::vector<ConsistencyFinding> findings;  // the blocks outside their band
};

Consistency diagnose_consistency(const RunRecord& run, const Metrics& m);

}  // namespace wingman::eval
