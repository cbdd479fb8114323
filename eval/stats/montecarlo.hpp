// Aggregation of N Monte Carlo runs of one scenario variant (paper Fig. 11, docs/design.md, evaluation): the
// average NEES per step with the two-sided 95 % chi^2 bounds for N runs,
// [chi2_0.025(dof N) / N, chi2_0.975(dof N) / N], the fraction of steps inside them per phase,
// and the mean and spread of the Table 4 metrics per phase. Reads what `wingman run` wrote.
// Because the fraction inside is itself random (eval/metrics/nees_null.hpp), each phase also gets the
// runs' mean NEES with a confidence interval and what an exactly consistent filter with the same
// error correlation would show, and, on request, the per-step test on independent batches of
// the runs beside how many of them a consistent filter would pass.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "eval/metrics/run_record.hpp"
#include "eval/stats/run_set.hpp"

namespace wingman::eval {

struct Spread {
  double mean = kNaN, std = kNaN, min = kNaN, max = kNaN;
  int n = 0;
};
Spread spread_of(const std::vector<double>& values);

struct AgentSpread {
  std::string agent;
  Spread mse[3];  // x, y, z over the runs
};

// One agent's position and velocity NEES (3 dof each; a consistent filter averages 3), the
// per-run phase means spread over the runs: which block makes the total NEES off.
struct BlockNees {
  std::string agent;
  Spread position, velocity;
};

struct MonteCarloPhase {
  std::string name;  // a phase, or "total"
  double t_start = 0, t_end = 0;
  int steps = 0;          // steps with an average NEES
  int inside = 0;         // of which inside the bounds
  double fraction_inside = kNaN;
  double mean_nees = kNaN;  // average NEES averaged over the phase's steps
  // Each run's mean NEES over the phase, spread over the runs: runs are independent, so
  // mean ± 1.96 std / sqrt(runs) is a 95 % interval for the filter's phase mean (normal
  // approximation), which accounts for the correlation in time that the per-step bounds ignore.
  Spread run_mean_nees;
  // An exactly consistent filter with these runs' NEES autocorrelation: the median fraction of
  // the phase's steps inside the bounds, and the probability of a fraction under kInsideTarget.
  double consistent_median_inside = kNaN;
  double consistent_p_below_target = kNaN;
  std::vector<AgentSpread> agents;  // Table 4 of the phase over the runs
  std::vector<BlockNees> blocks;    // phases only (empty for "total" and for older runs)
};

// The fraction of steps inside the 95 % bounds a consistent filter keeps in every phase.
inline constexpr double kInsideTarget = 0.9;

// 95 % half-width of the interval for the phase mean NEES from the runs' phase means.
double mean_nees_halfwidth95(const Spread& run_means);

// The per-step test applied to independent batches: runs [first, first + size) of the sorted
// runs, each batch with its own bounds for `size` runs. It passes when every phase has at least
// kInsideTarget of its steps inside them.
struct Batch {
  std::size_t first = 0, size = 0;
  std::string label;  // "runs 1-50" unless the caller names them (by seed)
  std::vector<double> fraction_inside;  // per phase, "total" left out
  bool passed = false;
  double consistent_p_pass = kNaN;  // an exactly consistent filter with this batch's correlation
};
struct BatchTest {
  std::size_t batch_size = 0;
  std::vector<Batch> batches;
  int passed = 0;
  // A consistent filter: the expected number of passing batches, and the probability of at most
  // `passed` of them (each batch independent, with its own pass probability).
  double consistent_expected_passes = kNaN;
  double consistent_p_at_most_passed = kNaN;
};

struct MonteCarloSummary {
  std::string label;  // the variant, or the scenario name
  int runs = 0;
  int dof = 0;
  double lower = kNaN, upper = kNaN;  // bounds of the average NEES
  std::vector<double> t, average_nees;  // per step
  std::vector<MonteCarloPhase> phases;  // every phase, then "total"
  // Integral time scale of the runs' NEES (s): a phase holds about its length / this many
  // independent looks at the filter's consistency.
  double nees_correlation_time = kNaN;
  // Probability that an exactly consistent filter puts every phase (not "total") at or above
  // kInsideTarget, with these runs' error correlation.
  double consistent_p_all_phases_at_target = kNaN;
  std::optional<BatchTest> batches;  // when asked for (`wingman montecarlo --batch`)
};

// P(X <= k) for X the number of successes of independent trials with these probabilities.
double poisson_binomial_cdf(const std::vector<double>& p, int k);

// Splits run_dirs (in the given order) into consecutive batches of batch_size, the remainder
// left out, and tests each. Throws std::invalid_argument when fewer than one batch fits.
BatchTest test_batches(const std::string& label, const std::vector<std::filesystem::path>& run_dirs,
                       std::size_t batch_size);
// The same on runs already read (no file is read again but the first run's steps.csv per batch).
BatchTest test_batches(const std::string& label, const RunSet& runs, std::size_t batch_size);

// Aggregates the results directories of N runs of one variant (each holding metrics.json and
// steps.csv). Throws std::runtime_error naming the file when one is missing or malformed, or
// when the runs do not have the same steps.
MonteCarloSummary aggregate_runs(const std::string& label,
                                 const std::vector<std::filesystem::path>& run_dirs);
MonteCarloSummary aggregate_runs(const std::string& label, const RunSet& runs);

// The message of a run's recorded numerical failure (metrics.json's numerical_failure, see
// estimator.on_numerical_failure), or "" when it has none. Such a run stops early: a failed seed.
std::string recorded_numerical_failure(const std::filesystem::path& run_dir);

// What montecarlo.json says about the study besides its summaries.
struct MonteCarloProvenance {
  std::string scenario;       // the scenario file
  std::string scenario_hash;  // FNV-1a 64 of its bytes, hex
  std::vector<std::uint64_t> seeds;                                // aggregated
  std::vector<std::pair<std::uint64_t, std::string>> failed;      // seed, why
};

// montecarlo.json ({scenario, scenario_fnv1a64, seeds, failed_seeds, variants: every summary})
// and nees.csv (t and, per summary, average NEES and bounds), each written atomically.
void write_monte_carlo(const std::vector<MonteCarloSummary>& summaries,
                       const std::filesystem::path& dir, const MonteCarloProvenance& prov = {});
// A readable table: per summary and phase, the fraction of steps inside the bounds and the Table
// 4 means with their standard deviations.
std::string format_monte_carlo(const std::vector<MonteCarloSummary>& summaries);

}  // namespace wingman::eval
