#include "app/cli/cli_options.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "app/cli/subcommand.hpp"
#include "render/frame_cache.hpp"

namespace wingman::app {

void add_variant_option(CLI::App* cmd, std::vector<std::string>& variants, const std::string& help) {
  // One name per --variant, so that a positional argument after it stays positional.
  cmd->add_option("--variant", variants, help + " (repeatable: each in turn)")->allow_extra_args(false);
}

int for_each_variant(const std::vector<std::string>& variants, const std::function<int(const std::string&)>& one) {
  if (variants.empty()) return one("");
  for (const auto& v : variants)
    if (const int rc = one(v); rc != 0) return rc;
  return 0;
}

void add_step_limit(CLI::App* cmd, StepLimit& limit) {
  auto* d = cmd->add_option("--duration", limit.duration,
                            "Only the first S seconds (phases and outages cut there)");
  auto* f = cmd->add_option("--frames", limit.frames, "Only the first N frames (t = 0 included)");
  d->excludes(f);
}

std::uint64_t FrameCacheCli::max_bytes() const {
  try {
    const std::uint64_t bytes = render::parse_byte_size(size);
    if (bytes < (64ull << 20)) throw std::invalid_argument(fmt::format("'{}': at least 64M", size));
    return bytes;
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(fmt::format("--frame-cache-size {}", e.what()));
  }
}

FrameCacheOptions FrameCacheCli::resolve() const {
  if (dir.empty()) return {};
  FrameCacheOptions o{std::filesystem::absolute(dir).string(), max_bytes()};
  try {
    render::FrameCache check(o.dir, o.max_bytes);  // creates it, or says why it cannot
  } catch (const std::runtime_error& e) {
    throw io::UsageError(fmt::format("--frame-cache {}", e.what()));
  }
  return o;
}

void add_frame_cache_options(CLI::App* cmd, FrameCacheCli& cache, const std::string& what) {
  cmd->add_option("--frame-cache", cache.dir,
                  "Rendered scenarios: keep every rendered frame in this directory, keyed by a hash of "
                  "everything that decides its pixels, and read it back instead of rendering it again "
                  "(same results; safe to share between concurrent runs; docs/frame_cache.md). " + what);
  cmd->add_option("--frame-cache-size", cache.size,
                  "Bound on the frame cache's size: the least recently used frames go first past it "
                  "(e.g. 40G, 512M; default 40G)");
}

void add_force_flag(CLI::App* cmd, bool& force) {
  cmd->add_flag("--force", force,
                "Replace the output directory if it already holds wingman output (by default an "
                "existing one is refused; a directory wingman did not write is never replaced)");
}

void stage_output(std::optional<io::ResultsDir>& staged, const std::filesystem::path& out,
                  const std::string& kind, bool force) {
  try {
    staged.emplace(out, io::ResultsDir::Options{kind, force});
  } catch (const std::runtime_error& e) {
    throw io::UsageError(e.what());
  }
  for (const auto& note : staged->notes()) fmt::print(stderr, "note: {}\n", note);
}

}  // namespace wingman::app
