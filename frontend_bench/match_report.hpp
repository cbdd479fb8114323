// The matching benchmark's outputs: the table on stdout, and in a results directory
// scores.json (every group's counts and ratios at every threshold), scores.csv (one row per
// method and group), curves.csv and plots/match_curves.png, and with conditions conditions.csv
// and plots/conditions.png (docs/frontend.md).
#pragma once

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "frontend_bench/match_files.hpp"
#include "frontend_bench/match_score.hpp"

namespace wingman::frontend_bench {

struct MethodScores {
  std::string name;
  // Detection + description per frame: built-in detectors timed here, or a frontend's own
  // timings.csv (match_files.hpp); NaN otherwise.
  double detect_ms_per_frame = std::numeric_limits<double>::quiet_NaN();      // wall time
  double detect_cpu_ms_per_frame = std::numeric_limits<double>::quiet_NaN();  // process CPU time
  double keypoints_per_frame = std::numeric_limits<double>::quiet_NaN();
  std::vector<GroupScore> groups;
};

// How the benchmark matched the built-in detectors' features itself (bench-frontend); absent for
// a frontend's own matches (score-matches).
struct MatcherOptions {
  double ratio = 0;   // Lowe's ratio test
  bool mutual = true;  // cross-check
  int max_features = 0;
};

struct ConditionInfo {
  std::string name, dataset;
};

struct MatchReport {
  std::string dataset;
  std::vector<ConditionInfo> conditions;  // besides the reference
  std::size_t pairs = 0, temporal_pairs = 0, cross_pairs = 0, same_instant_pairs = 0;
  ScoreOptions options;
  // The pairs' limit to the dataset's first seconds or frames (--duration / --frames), if any.
  std::optional<double> duration_s;
  std::optional<int> frames;
  std::optional<MatcherOptions> matcher;
  std::vector<MethodScores> methods;
};

MatchReport make_report(const std::string& dataset, const Conditions& sets, const std::vector<FramePair>& pairs,
                        const ScoreOptions& options);

// "99 pairs (84 temporal, 15 cross-UAV)", with the same-instant pairs and conditions when there are.
std::string describe_pairs(const MatchReport& report);

// One row per method and group (with a condition column when there are conditions); precision
// and recall at 1, 3 and 5 px where those thresholds are scored (else the first three),
// repeatability and localisation at localisation_px.
std::string format_match_table(const MatchReport& report);

// scores.json, scores.csv, curves.csv and, with conditions, conditions.csv into dir (which must
// exist), and the plots unless `plots` is false. Throws std::runtime_error naming a file that
// cannot be written.
void write_match_report(const MatchReport& report, const std::filesystem::path& dir, bool plots);

}  // namespace wingman::frontend_bench
