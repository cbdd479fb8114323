// The finished runs of one variant with each run's metrics.json parsed once: aggregate_runs,
// test_batches (once per batch) and compare_paired all read the same files, which they used to
// read and parse again each time. Slices share the parsed files.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <vector>

namespace wingman::eval {

class RunSet {
 public:
  RunSet();  // no runs
  // Reads <dir>/metrics.json of every dir; std::runtime_error naming the file when one is missing
  // or not valid JSON.
  explicit RunSet(std::vector<std::filesystem::path> dirs);

  std::size_t size() const { return dirs_.size(); }
  bool empty() const { return dirs_.empty(); }
  const std::vector<std::filesystem::path>& dirs() const { return dirs_; }
  const std::filesystem::path& dir(std::size_t i) const { return dirs_.at(i); }
  // Runs first .. first + count - 1, without reading anything again.
  RunSet slice(std::size_t first, std::size_t count) const;

  struct Parsed;  // eval/output/json_file.hpp: the parsed files, for eval's own sources
  const Parsed& parsed() const { return *parsed_; }
  std::size_t offset() const { return offset_; }

 private:
  std::vector<std::filesystem::path> dirs_;
  std::shared_ptr<const Parsed> parsed_;
  std::size_t offset_ = 0;
};

}  // namespace wingman::eval
