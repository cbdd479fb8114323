// Loading a dataset written by `wingman render` for a replay (`wingman slam`, `wingman
// bench-frontend`): the dataset, validated, and the scenario it was rendered from (its own
// scenario.yaml, with the dataset's variant and seed), shortened to the frames it holds.
#pragma once

#include <filesystem>
#include <string>

#include "datasets/dataset.hpp"
#include "app/config/run_config.hpp"

namespace wingman::app {

struct Replay {
  datasets::Dataset dataset;
  RunConfig scenario;
  std::filesystem::path scenario_path;  // DIR/scenario.yaml
};

// `variant` empty: the one the dataset was rendered with (else the first). Checks the dataset
// against its scenario (rate, cameras, agents) and verifies every frame (checksums.csv) before
// returning, with a progress line unless `quiet`. Throws io::UsageError naming the file for a
// dataset or scenario that cannot be used.
Replay load_replay(const std::string& dir, const std::string& variant, bool quiet = false);

}  // namespace wingman::app
