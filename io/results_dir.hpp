// An atomic output directory (a results directory, or a dataset): everything is written into a
// sibling staging directory "<final>.partial-<pid>" and commit() renames it into place, so a
// crashed or interrupted run never leaves a half-written directory under the final name.
// An existing directory is never replaced unless the caller says so (`--force`), and even then
// only if it carries the marker file that commit() writes, so a typo in the output path cannot
// delete someone's data. Staging directories that killed processes left beside the target are
// found when the next one is made: removed when their process is gone, named otherwise.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace wingman::io {

class ResultsDir {
 public:
  static constexpr const char* kMarker = ".wingman-results";

  struct Options {
    std::string kind = "results";  // what the marker says it holds: "results" or "dataset"
    bool force = false;            // replace an existing directory of ours (`--force`)
  };

  // Creates the parent directories and an empty staging directory. Throws std::runtime_error,
  // before any work, if final_dir exists and is not ours, or is ours and force is not set.
  ResultsDir(std::filesystem::path final_dir, Options options);
  explicit ResultsDir(std::filesystem::path final_dir);  // kind "results", no force
  ResultsDir(const ResultsDir&) = delete;
  ResultsDir& operator=(const ResultsDir&) = delete;
  // Removes the staging directory unless commit() succeeded.
  ~ResultsDir();

  const std::filesystem::path& staging() const { return staging_; }
  const std::filesystem::path& final_dir() const { return final_; }
  bool committed() const { return committed_; }
  // What the constructor did about leftovers of killed processes, one line each.
  const std::vector<std::string>& notes() const { return notes_; }

  // Writes the marker into the staging directory and renames it to final_dir (replacing a
  // previous one only with force). Throws std::runtime_error (the staging directory is kept
  // until destruction) if final_dir appeared meanwhile and may not be replaced, or a rename fails.
  void commit();

  // Removes every "<name>.partial-<pid>" directly in `dir` whose process is gone (a staging
  // directory is never complete); returns one note per directory removed or left to its
  // running process.
  static std::vector<std::string> remove_stale_staging(const std::filesystem::path& dir);

  // True if dir is a directory holding the marker file.
  static bool is_results_dir(const std::filesystem::path& dir);
  // The kind a marked directory holds ("results", "dataset"); "" when it is not ours.
  static std::string kind_of(const std::filesystem::path& dir);

 private:
  std::filesystem::path final_, staging_;
  Options options_;
  bool committed_ = false;
  std::vector<std::string> notes_;
};

}  // namespace wingman::io
