// Plots of a run with gnuplot (pngcairo). Each plot is a script plots/<name>.gp next to its
// PNG that reads steps.csv by column name, so a user can edit it and rerun
// `gnuplot plots/<name>.gp` from the results directory. Time plots mark the phase boundaries.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "eval/stats/montecarlo.hpp"
#include "eval/metrics/run_record.hpp"

namespace wingman::eval {

// True if a gnuplot with the pngcairo terminal can be run from PATH.
bool gnuplot_available();

// Writes into <results_dir>/plots/: trajectory_<agent>.png (truth and estimate per axis,
// Fig. 9), errors_<agent>.png (|error| per axis with 3 sigma, Fig. 10), landmarks.png and
// nees.png (left out when the run has no finite NEES), each with its .gp script.
// Closed-loop runs add closed_loop_trajectories.png (top view, Fig. 13), formation_errors.png
// (Fig. 14, from formation.csv) and closed_loop_errors.png (error norms, Fig. 15).
// results_dir must already hold steps.csv (write_steps_csv). Returns the PNGs written.
// Throws std::runtime_error naming the plot if gnuplot is missing or fails.
std::vector<std::filesystem::path> write_plots(const RunRecord& run,
                                               const std::filesystem::path& results_dir);

// |error| per axis of one agent for several runs overlaid (e.g. multi- vs single-UAV,
// Fig. 10). Reads <dir>/steps.csv of each run by absolute path and the phase boundaries from
// the first run's metrics.json if it has one; the script is written next to out_png with the
// extension .gp. Throws std::invalid_argument if the sizes differ or a run lacks the agent,
// std::runtime_error if gnuplot fails.
void plot_comparison(const std::vector<std::string>& results_dirs,
                     const std::vector<std::string>& labels, const std::string& agent,
                     const std::string& out_png);

// The average NEES of Monte Carlo runs over time with its 95 % bounds and the phase
// boundaries, every summary (e.g. multi- and single-UAV) in one plot (the paper's Fig. 11):
// <dir>/plots/montecarlo_nees.png and .gp, reading <dir>/nees.csv (write_monte_carlo).
std::filesystem::path plot_monte_carlo_nees(const std::vector<MonteCarloSummary>& summaries,
                                            const std::filesystem::path& dir);

// The matching benchmark's curves (docs/frontend.md, benchmark of feature frontends): precision,
// recall and repeatability against the pixel threshold, one line per method and pair type, in
// <dir>/plots/match_curves.png and .gp, reading <dir>/curves.csv (columns method, type,
// baseline, threshold_px, repeatability, precision, recall).
std::filesystem::path plot_match_curves(const std::vector<std::string>& methods,
                                        const std::filesystem::path& dir);

// The matching benchmark per condition (docs/frontend.md, conditions): precision, recall and
// repeatability at threshold_px against the condition (conditions[0] the reference), one line per
// method and pair type (solid: same-instant, dashed: temporal, dotted: cross-UAV), in
// <dir>/plots/conditions.png and .gp, reading <dir>/conditions.csv (columns method, type,
// condition_index, condition, pairs, threshold_px, precision, recall, repeatability).
std::filesystem::path plot_conditions(const std::vector<std::string>& methods,
                                      const std::vector<std::string>& conditions, double threshold_px,
                                      const std::filesystem::path& dir);

}  // namespace wingman::eval
