#include "app/cli/results_layout.hpp"

#include <fmt/core.h>

#include "eval/metrics/metrics.hpp"
#include "eval/output/plots.hpp"
#include "eval/output/writers.hpp"

namespace wingman::app {

std::filesystem::path variant_dir(const io::ResultsDir& staged, const RunConfig& scn, bool several) {
  return several || !scn.variant.empty() ? staged.staging() / scn.variant : staged.staging();
}

void write_variant(const eval::RunRecord& rec, const RunConfig& scn, const std::filesystem::path& dir, bool plots,
                   bool quiet) {
  std::filesystem::create_directories(dir);
  const eval::Metrics metrics = eval::compute_metrics(rec);
  eval::write_results(metrics, rec, dir);
  write_config(scn, dir / "config.yaml");
  if (plots) eval::write_plots(rec, dir);
  if (!quiet) fmt::print("{}\n", eval::format_summary(metrics, rec));
}

void publish_results(io::ResultsDir& staged, const RunConfig& scn, const std::filesystem::path& out, bool quiet) {
  copy_scenario(scn, staged.staging());
  staged.commit();
  if (!quiet) fmt::print("results: {}\n", out.string());
}

}  // namespace wingman::app
