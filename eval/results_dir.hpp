// An atomic results directory: everything is written into a sibling staging directory
// "<final>.partial-<pid>" and commit() renames it into place, so a crashed or interrupted run
// never leaves a half-written results directory under the final name. An existing directory
// is replaced only if it carries the marker file that commit() writes, so a typo in the
// output path cannot delete someone's data.
#pragma once

#include <filesystem>

namespace wingman::eval {

class ResultsDir {
 public:
  static constexpr const char* kMarker = ".wingman-results";

  // Creates the parent directories and an empty staging directory (removing a stale one left
  // by an earlier process with the same pid). Throws std::runtime_error if final_dir exists
  // and is not a wingman results directory, so a run fails before doing any work.
  explicit ResultsDir(std::filesystem::path final_dir);
  ResultsDir(const ResultsDir&) = delete;
  ResultsDir& operator=(const ResultsDir&) = delete;
  // Removes the staging directory unless commit() succeeded.
  ~ResultsDir();

  const std::filesystem::path& staging() const { return staging_; }
  const std::filesystem::path& final_dir() const { return final_; }
  bool committed() const { return committed_; }

  // Writes the marker into the staging directory and renames it to final_dir, replacing a
  // previous results directory there. Throws std::runtime_error (the staging directory is
  // kept until destruction) if final_dir is not a results directory or a rename fails.
  void commit();

  // True if dir is a directory holding the marker file.
  static bool is_results_dir(const std::filesystem::path& dir);

 private:
  std::filesystem::path final_, staging_;
  bool committed_ = false;
};

}  // namespace wingman::eval
