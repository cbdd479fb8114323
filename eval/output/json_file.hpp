// Reading a JSON file that wingman wrote, for eval's own sources only (nlohmann-json is a private
// dependency of the library): errors name the file.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "eval/stats/run_set.hpp"

namespace wingman::eval {

// The parsed file; std::runtime_error "<path>: cannot open" or "<path>: not valid JSON: ...".
nlohmann::json read_json_file(const std::filesystem::path& path);

struct RunSet::Parsed {
  std::vector<nlohmann::json> metrics;  // one per run of the set it was read for
};

// Run i's metrics.json.
inline const nlohmann::json& run_metrics(const RunSet& runs, std::size_t i) {
  return runs.parsed().metrics.at(runs.offset() + i);
}

}  // namespace wingman::eval
