// The determinism check (`wingman check A --against B`): two results trees of the same scenario
// and seed (results directories, their variants, Monte Carlo directories) must hold the same
// data, timings aside. Every data file under either tree is compared with its namesake:
//   CSV         row by row and column by column, the timing columns (t_*_ms) left out, an
//               empty field and "nan" both meaning no value;
//   JSON        key by key, without wall times, timings (keys ending _ms, timings_ms,
//               *_ms_per_step), the software version, the scenario file's path and the
//               frame cache's use (frame_cache: hits and misses differ, the frames do not);
//   YAML, TUM, PLY, TXT   line by line, comment lines (#) of YAML left out (they name paths).
// Plots, videos, logs and images are not compared (they carry timings or encoder state).
// With a relative tolerance, two numbers (a CSV field, a JSON number, a whitespace-separated word
// of a text line) are the same when |a - b| <= tol max(|a|, |b|, 1): results that differ only by
// the rounding of another order of the same arithmetic.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace wingman::eval {

struct TreeComparison {
  struct File {
    std::string path;        // relative to the trees
    std::string difference;  // the first one ("only in <tree>" for a file one tree lacks); "" when the same
  };
  std::vector<File> files;  // every data file of either tree, sorted
  int differing() const;
  bool identical() const { return differing() == 0; }
};

// Throws CheckInputError (eval/regression/metric_set.hpp) when either is not a directory holding results.
TreeComparison compare_results_trees(const std::filesystem::path& a, const std::filesystem::path& b,
                                     double rel_tol = 0);

// The first difference of two files of the same kind ("" when the same), named by row and
// column or key path.
std::string first_difference(const std::filesystem::path& a, const std::filesystem::path& b, double rel_tol = 0);

}  // namespace wingman::eval
