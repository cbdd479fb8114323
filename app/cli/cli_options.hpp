// Options that mean the same on every command that takes them: --variant (repeatable: each named
// variant in turn) and --duration S / --frames N (only the first S seconds, or the first N frames
// t = 0, dt, ..., of a run; phases and outages are cut there), and --force with the staged output
// directory every writing command opens the same way.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/pipeline/frame_producer.hpp"
#include "app/config/run_config.hpp"
#include "app/config/step_limit.hpp"
#include "io/results_dir.hpp"

namespace CLI {
class App;
}

namespace wingman::app {

void add_variant_option(CLI::App* cmd, std::vector<std::string>& variants, const std::string& help);
// Runs `one` for each named variant, or once with "" when none was named; returns the first
// non-zero exit code, or 0.
int for_each_variant(const std::vector<std::string>& variants, const std::function<int(const std::string&)>& one);

void add_step_limit(CLI::App* cmd, StepLimit& limit);

// --frame-cache DIR and --frame-cache-size SIZE (render/frame_cache.hpp).
struct FrameCacheCli {
  std::string dir;
  std::string size = "40G";
  // The size bound; a io::UsageError naming --frame-cache-size when it is not a size of 64M or more.
  std::uint64_t max_bytes() const;
  // The options for RendererFrames: dir made absolute and created (a io::UsageError naming
  // --frame-cache when it cannot be), the size checked.
  FrameCacheOptions resolve() const;
};
// `what` says when the cache is used (run: only with the option; montecarlo: by default).
void add_frame_cache_options(CLI::App* cmd, FrameCacheCli& cache, const std::string& what);

// --force: replace an existing output directory of wingman's (never a foreign one).
void add_force_flag(CLI::App* cmd, bool& force);
// Opens the staged output directory `out` (kind "results" or "dataset") into `staged`: refused
// with a io::UsageError, before any work, when `out` exists and --force was not given; leftovers of
// killed processes beside it are cleaned up and named on stderr.
void stage_output(std::optional<io::ResultsDir>& staged, const std::filesystem::path& out,
                  const std::string& kind, bool force);

}  // namespace wingman::app
