// What `wingman pairs`, `wingman score-matches` and `wingman bench-frontend` share: the pair
// list's options, the scoring options, the staged results directory of a matching benchmark, and
// the built-in detectors run outside the SLAM loop into the benchmark's file format
// (eval/match_files.hpp, docs/frontend.md).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "datasets/dataset.hpp"
#include "eval/match_files.hpp"
#include "eval/match_report.hpp"
#include "eval/match_score.hpp"
#include "eval/results_dir.hpp"
#include "vision/descriptor_match.hpp"
#include "vision/features.hpp"

namespace CLI {
class App;
}

namespace wingman::app {

// --pairs FILE, or the dataset's own pairs with --stride / --gap / --no-cross.
struct PairCli {
  std::string file;
  eval::PairOptions options;
  bool no_cross = false;
};
void add_pair_options(CLI::App* cmd, PairCli& pairs, bool with_file);
// The pairs to score; a bad pairs file throws eval::MatchInputError, a bad option UsageError.
std::vector<eval::FramePair> load_pairs(const datasets::Dataset& ds, const PairCli& pairs);

// --baseline-bins E1,E2,...
void add_score_options(CLI::App* cmd, eval::ScoreOptions& options);


// --out DIR, --force, --no-plots, -q. open_match_output stages DIR before any work (a
// UsageError when it exists without --force, or gnuplot is missing without --no-plots);
// publish_match_report prints the table and, with DIR, writes the report into the staging
// directory and renames it into place.
struct MatchOutput {
  std::string out;
  bool force = false, no_plots = false, quiet = false;
};
void add_match_output_options(CLI::App* cmd, MatchOutput& output);
void open_match_output(const MatchOutput& output, std::optional<eval::ResultsDir>& staged);
void publish_match_report(const eval::MatchReport& report, const MatchOutput& output,
                          std::optional<eval::ResultsDir>& staged);

// One built-in detector outside the SLAM loop: each frame of the pairs detected and described
// once (timed), each pair matched by descriptor, keypoints and matches written under dir in the
// benchmark's file format.
struct BuiltinFrontendOptions {
  vision::FeatureSettings features;
  vision::DescriptorMatchSettings matching;
};
struct BuiltinFrontendRun {
  int frames = 0;
  double detect_ms = 0;      // detection + description, all frames, wall time
  double detect_cpu_ms = 0;  // the same in CPU time of the process (all of OpenCV's threads)
  long keypoints = 0;
};
BuiltinFrontendRun run_builtin_frontend(const datasets::Dataset& ds,
                                        const std::vector<eval::FramePair>& pairs,
                                        const BuiltinFrontendOptions& options,
                                        const std::filesystem::path& dir,
                                        const std::function<void(int, int)>& progress = {});

}  // namespace wingman::app
