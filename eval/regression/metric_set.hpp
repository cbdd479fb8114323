// The numbers of a results directory or a Monte Carlo directory that a baseline can name
// (`wingman baseline`, `wingman check`, docs/check.md). A metric is a path into metrics.json,
// prefixed with the variant when the scenario has variants:
//   multi/table4.total.lead.mse.x     Table 4, total, the lead's MSE along x (m^2)
//   table5.total.final_mse.z          Table 5, final landmark MSE along z (m^2)
//   table3.landmarks.accepted_outlier_fraction, nees.mean, frontend.lead_detection_rate,
//   frontend.lead_error_px.mean, wall_time_s, timings_ms.update.mean, ...
// A results directory gives each metric one value; a Monte Carlo directory one per seed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::eval {

// Bad input to baseline/check: a directory that is not results, a metrics.json of another
// schema, a malformed baseline, a metric the results do not have. The message names the file
// (and line, and metric).
struct CheckInputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct MetricSet {
  std::filesystem::path dir;
  bool monte_carlo = false;
  std::string scenario;                // its name
  std::string software_version;        // of the first run read
  std::vector<std::uint64_t> seeds;    // one for a results directory
  std::vector<std::string> paths;      // every metric, in file order
  // Per metric, one value per seed (NaN where the file has null); every path is in paths.
  std::map<std::string, std::vector<double>> values;
  // Runs that failed: a recorded numerical failure ("<metrics.json>: <message>") or a Monte
  // Carlo seed montecarlo.json lists as failed ("<montecarlo.json>: seed N: <reason>").
  std::vector<std::string> failures;

  bool has(const std::string& path) const { return values.count(path) > 0; }
};

// Reads <dir>/metrics.json, <dir>/<variant>/metrics.json, or a Monte Carlo directory's
// montecarlo.json and runs/seed<N>[/<variant>]/metrics.json of the seeds it aggregated.
// CheckInputError when dir is none of these, or a file is missing, malformed, or of another
// schema version.
MetricSet read_metric_set(const std::filesystem::path& dir);

// Timings (wall_time_s, timings_ms.*, frontend.detect_busy_ms_per_step, frame_cache.*): they depend
// on the machine and on what the frame cache held.
bool is_timing_metric(const std::string& path);

// The metrics a baseline holds unless told otherwise: Table 4 totals per agent and axis, Table 5
// final per axis, every channel's accepted-outlier fraction, the NEES mean, the lead detection
// rate and mean pixel error (rendered runs), the wall time and the per-stage mean timings.
std::vector<std::string> default_metrics(const MetricSet& set);

// The metrics of set matching any of the shell globs (fnmatch, '*' crosses '.' and '/'), in
// the order of the globs. CheckInputError naming a glob that matches nothing.
std::vector<std::string> select_metrics(const MetricSet& set, const std::vector<std::string>& globs);

}  // namespace wingman::eval
