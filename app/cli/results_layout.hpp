// The results directory `wingman run` and `wingman slam` both write, so that `check`, `baseline`
// and a user's CI read them the same way: a variant's files in OUT/<variant>/ when the scenario
// has variants (or several run), in OUT/ otherwise, and the scenario beside them.
#pragma once

#include <filesystem>

#include "app/config/run_config.hpp"
#include "eval/metrics/run_record.hpp"
#include "io/results_dir.hpp"

namespace wingman::app {

std::filesystem::path variant_dir(const io::ResultsDir& staged, const RunConfig& scn, bool several);
// One variant's files into `dir`: metrics and records, config.yaml, plots unless `plots` is
// false; its summary on stdout unless quiet.
void write_variant(const eval::RunRecord& rec, const RunConfig& scn, const std::filesystem::path& dir, bool plots,
                   bool quiet);
// The scenario beside the variants, the directory renamed into place, its path on stdout.
void publish_results(io::ResultsDir& staged, const RunConfig& scn, const std::filesystem::path& out, bool quiet);

}  // namespace wingman::app
