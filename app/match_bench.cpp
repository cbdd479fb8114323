#include "app/match_bench.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <chrono>
#include <ctime>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "app/cli_options.hpp"
#include "app/subcommand.hpp"
#include "eval/plots.hpp"
#include "eval/results_dir.hpp"

namespace wingman::app {

namespace fs = std::filesystem;

void add_pair_options(CLI::App* cmd, PairCli& p, bool with_file) {
  if (with_file)
    cmd->add_option("--pairs", p.file,
                    "Pairs file (as `wingman pairs` writes it; default: the dataset's pairs with "
                    "--stride/--gap)");
  cmd->add_option("--stride", p.options.stride, "A pair starts at every N-th frame")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_option("--gap", p.options.gaps, "Temporal pairs: frame k with frame k + GAP (repeatable)")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_flag("--no-cross", p.no_cross, "No cross-UAV pairs");
}

std::vector<eval::FramePair> load_pairs(const datasets::Dataset& ds, const PairCli& p) {
  if (!p.file.empty()) return eval::read_pairs(p.file, ds);
  eval::PairOptions o = p.options;
  o.cross = !p.no_cross;
  try {
    auto pairs = eval::make_pairs(ds, o);
    if (pairs.empty()) throw UsageError(fmt::format("{}: no frame pairs (too few frames for the gaps?)", ds.root.string()));
    return pairs;
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

void add_score_options(CLI::App* cmd, eval::ScoreOptions& o) {
  cmd->add_option("--baseline-bins", o.baseline_edges_m,
                  "Edges of the baseline bins in metres, increasing (per pair type)")
      ->delimiter(',')->capture_default_str();
}

void add_match_output_options(CLI::App* cmd, MatchOutput& o) {
  cmd->add_option("--out,-o", o.out, "Results directory: scores.json, scores.csv, curves.csv, plots/");
  add_force_flag(cmd, o.force);
  cmd->add_flag("--no-plots", o.no_plots, "Skip the PNG plot (no gnuplot needed)");
  cmd->add_flag("--quiet,-q", o.quiet, "No progress lines");
}

void open_match_output(const MatchOutput& o, std::optional<eval::ResultsDir>& staged) {
  if (o.out.empty()) return;
  if (!o.no_plots && !eval::gnuplot_available())
    throw UsageError("gnuplot with the pngcairo terminal was not found; install it or pass --no-plots");
  stage_output(staged, o.out, "results", o.force);
}

void publish_match_report(const eval::MatchReport& report, const MatchOutput& o,
                          std::optional<eval::ResultsDir>& staged) {
  if (staged) {
    eval::write_match_report(report, staged->staging(), !o.no_plots);
    staged->commit();
  }
  fmt::print("{}", eval::format_match_table(report));
  if (staged) fmt::print("results: {}\n", o.out);
}

namespace {

// Features of the frames a few consecutive pairs share, detected once each.
class FeatureCache {
 public:
  FeatureCache(const datasets::Dataset& ds, const vision::FeatureExtractor& fx, const fs::path& dir,
               BuiltinFrontendRun& run)
      : ds_(ds), fx_(fx), dir_(dir), run_(run) {}
  const vision::Features& get(const std::string& agent, std::int64_t t_ns) {
    const auto key = std::make_pair(agent, t_ns);
    if (const auto it = cache_.find(key); it != cache_.end()) {
      order_.erase(std::find(order_.begin(), order_.end(), key));
      order_.push_back(key);
      return it->second;
    }
    if (order_.size() >= kMaxFrames) {
      cache_.erase(order_.front());
      order_.erase(order_.begin());
    }
    const cv::Mat image = ds_.load_image(agent, t_ns);
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    vision::Features f = fx_.detect(image);
    run_.detect_cpu_ms += 1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    run_.detect_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++run_.frames;
    run_.keypoints += f.size();
    if (!written_.count(key)) {  // a frame evicted and seen again is detected again, written once
      std::vector<eval::Keypoint> kps;
      for (const auto& k : f.keypoints) kps.push_back({{k.pt.x, k.pt.y}, k.response});
      eval::write_keypoints(eval::keypoints_file(dir_, agent, t_ns), kps);
      written_.insert(key);
    }
    order_.push_back(key);
    return cache_.emplace(key, std::move(f)).first->second;
  }

 private:
  static constexpr std::size_t kMaxFrames = 48;
  using Key = std::pair<std::string, std::int64_t>;
  const datasets::Dataset& ds_;
  const vision::FeatureExtractor& fx_;
  fs::path dir_;
  BuiltinFrontendRun& run_;
  std::map<Key, vision::Features> cache_;
  std::vector<Key> order_;
  std::set<Key> written_;
};

}  // namespace

BuiltinFrontendRun run_builtin_frontend(const datasets::Dataset& ds,
                                        const std::vector<eval::FramePair>& pairs,
                                        const BuiltinFrontendOptions& options, const fs::path& dir,
                                        const std::function<void(int, int)>& progress) {
  const vision::FeatureExtractor fx(options.features);
  BuiltinFrontendRun run;
  FeatureCache cache(ds, fx, dir, run);
  int done = 0;
  for (const auto& p : pairs) {
    const vision::Features& a = cache.get(p.agent_a, p.t_a);
    const vision::Features& b = cache.get(p.agent_b, p.t_b);
    std::vector<eval::Match> matches;
    for (const auto& m : vision::match_descriptors(a, b, options.matching)) matches.push_back({m.queryIdx, m.trainIdx});
    eval::write_matches(eval::matches_file(dir, p.id), matches);
    if (progress) progress(++done, static_cast<int>(pairs.size()));
  }
  return run;
}

}  // namespace wingman::app
