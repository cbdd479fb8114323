// Paired comparison of two variants of a scenario run on the same seeds (e.g. whether the
// single-UAV baseline is worse than multi-UAV). Seed by seed the two variants share the truth and the sensor
// noise, so their difference is measured far better paired than from the two means: per agent
// and axis of the Table 4 totals and per axis of Table 5's final landmark MSE, on how many seeds
// B is worse than A, the exact two-sided sign test of "as often worse as better", and the
// geometric-mean ratio B / A with a 95 % Student-t interval over the seeds' log ratios (MSEs are
// skewed; their logs are close to normal, and a ratio reads the same for every axis). The same
// per phase of Table 4 follows, since a difference in a total is often one phase's.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "eval/metrics/run_record.hpp"
#include "eval/stats/run_set.hpp"

namespace wingman::eval {

struct PairedRow {
  std::string quantity;  // "table4" (an agent's total MSE) or "table5" (landmarks, final MSE)
  std::string agent;     // Table 4's agent; "landmarks" for Table 5
  std::string phase;     // Table 4's phase name; empty for the totals and Table 5
  int axis = 0;          // 0, 1, 2: x, y, z
  int seeds = 0;         // seeds where both variants have the value
  int b_worse = 0;       // of which B's MSE is larger than A's
  double sign_p = kNaN;  // two-sided exact sign test
  // exp(mean log(B / A)) and its 95 % interval (NaN with fewer than two seeds).
  double ratio = kNaN, ratio_lo = kNaN, ratio_hi = kNaN;
};

struct PairedComparison {
  std::string a, b;  // variant labels: B is compared against A
  int seeds = 0;
  std::vector<PairedRow> rows;
};

// P of a split at least as uneven as k of n under a fair coin (two-sided, capped at 1).
double sign_test_p(int k, int n);
// The p-quantile of Student's t with `dof` degrees of freedom (p in (0, 1), dof >= 1).
double student_t_quantile(double p, double dof);

// Row from the per-seed values of one quantity (a[i] and b[i] from the same seed; a pair where
// either is not a positive finite number is left out).
PairedRow compare_values(const std::vector<double>& a, const std::vector<double>& b);

// Reads metrics.json of dirs_a[i] and dirs_b[i] (the same seed) for every i: Table 4's agents
// that both variants have, in A's order, then Table 5, then Table 4 per phase of A's first seed
// (matched by name; a seed without the phase or the agent there is left out of that row). Throws std::runtime_error naming the file
// when one is missing or malformed, std::invalid_argument when the lists differ in length.
PairedComparison compare_paired(const std::string& a, const std::vector<std::filesystem::path>& dirs_a,
                                const std::string& b, const std::vector<std::filesystem::path>& dirs_b);
// The same on runs already read.
PairedComparison compare_paired(const std::string& a, const RunSet& runs_a, const std::string& b,
                                const RunSet& runs_b);

// A readable table of one comparison.
std::string format_paired(const PairedComparison& c);
// The comparisons as JSON (comparison.json of `wingman montecarlo`).
void write_paired(const std::vector<PairedComparison>& comparisons, const std::filesystem::path& path);

}  // namespace wingman::eval
