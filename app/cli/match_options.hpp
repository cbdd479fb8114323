// What `wingman pairs`, `wingman score-matches` and `wingman bench-frontend` share: the pair
// list's options, the scoring options, the staged results directory of a matching benchmark (the
// benchmark itself: frontend_bench/).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "datasets/dataset.hpp"
#include "frontend_bench/conditions.hpp"
#include "frontend_bench/match_files.hpp"
#include "frontend_bench/match_report.hpp"
#include "frontend_bench/match_score.hpp"
#include "app/config/step_limit.hpp"
#include "io/results_dir.hpp"

namespace CLI {
class App;
}

namespace wingman::app {

// --pairs FILE, or the dataset's own pairs with --stride / --gap / --no-cross; --condition
// NAME=DIR (repeatable) adds a condition dataset; --duration S / --frames N keep the pairs whose
// frames both lie within the dataset's first S seconds or N frames.
struct PairCli {
  std::string file;
  std::vector<std::string> conditions;  // NAME=DIR
  frontend_bench::PairOptions options;
  bool no_cross = false;
  StepLimit limit;
};
void add_pair_options(CLI::App* cmd, PairCli& pairs, bool with_file);
// The reference dataset with the --condition datasets, each read and checked against it: a bad
// NAME=DIR throws io::UsageError, a condition that does not image the reference's flight
// datasets::DatasetError naming its file.
frontend_bench::Conditions load_conditions(const datasets::Dataset& reference, const PairCli& pairs);
// The pairs to score, limited, saying on stderr (unless quiet) how many the limit left out; a bad
// pairs file throws frontend_bench::MatchInputError, a bad option or no pair left io::UsageError.
std::vector<frontend_bench::FramePair> load_pairs(const frontend_bench::Conditions& sets, const PairCli& pairs,
                                                  bool quiet);

// --baseline-bins E1,E2,...
void add_score_options(CLI::App* cmd, frontend_bench::ScoreOptions& options);


// --out DIR, --force, --no-plots, -q. open_match_output stages DIR before any work (a
// io::UsageError when it exists without --force, or gnuplot is missing without --no-plots);
// publish_match_report prints the table and, with DIR, writes the report into the staging
// directory and renames it into place.
struct MatchOutput {
  std::string out;
  bool force = false, no_plots = false, quiet = false;
};
void add_match_output_options(CLI::App* cmd, MatchOutput& output);
void open_match_output(const MatchOutput& output, std::optional<io::ResultsDir>& staged);
void publish_match_report(const frontend_bench::MatchReport& report, const MatchOutput& output,
                          std::optional<io::ResultsDir>& staged);

}  // namespace wingman::app
