#include "frontend_bench/match_report.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"
#include "eval/output/plots.hpp"

namespace wingman::frontend_bench {

namespace fs = std::filesystem;

namespace {

constexpr int kSchemaVersion = 2;  // 2: conditions

// Indices of the thresholds the table shows: 1, 3 and 5 px when scored, else the first three.
std::vector<std::size_t> table_columns(const ScoreOptions& o) {
  std::vector<std::size_t> cols;
  for (double want : {1.0, 3.0, 5.0}) {
    const auto it = std::find(o.thresholds_px.begin(), o.thresholds_px.end(), want);
    if (it != o.thresholds_px.end()) cols.push_back(static_cast<std::size_t>(it - o.thresholds_px.begin()));
  }
  if (cols.size() == 3) return cols;
  cols.clear();
  for (std::size_t i = 0; i < std::min<std::size_t>(3, o.thresholds_px.size()); ++i) cols.push_back(i);
  return cols;
}

// The threshold index equal to localisation_px, or the last one below it.
std::size_t main_column(const ScoreOptions& o) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < o.thresholds_px.size(); ++i)
    if (o.thresholds_px[i] <= o.localisation_px) k = i;
  return k;
}

std::string pct(double v) { return std::isfinite(v) ? fmt::format("{:.1f}", 100 * v) : "-"; }
std::string num(double v, int digits) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : "-"; }
nlohmann::json jnum(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

double per(long n, long d) { return d > 0 ? static_cast<double>(n) / static_cast<double>(d) : NAN; }

nlohmann::json group_json(const GroupScore& g, const ScoreOptions& o) {
  const MatchCounts& c = g.counts;
  nlohmann::json j{{"condition", g.condition}, {"type", g.type}, {"baseline", g.baseline}, {"pairs", c.pairs},
                   {"keypoints_a", c.keypoints_a}, {"keypoints_b", c.keypoints_b},
                   {"covisible", c.covisible}, {"matches", c.matches},
                   {"localised", c.localised}, {"localisation_px", jnum(c.localisation_px())}};
  for (std::size_t t = 0; t < o.thresholds_px.size(); ++t)
    j["thresholds"].push_back({{"px", o.thresholds_px[t]},
                               {"repeatable", c.repeatable[t]},
                               {"correct", c.correct[t]},
                               {"correct_a", c.correct_a[t]},
                               {"repeatability", jnum(c.repeatability(t))},
                               {"precision", jnum(c.precision(t))},
                               {"recall", jnum(c.recall(t))}});
  return j;
}

std::string scores_json(const MatchReport& r) {
  nlohmann::json j{{"schema_version", kSchemaVersion},
                   {"dataset", r.dataset},
                   {"pairs", r.pairs},
                   {"temporal_pairs", r.temporal_pairs},
                   {"cross_pairs", r.cross_pairs},
                   {"same_instant_pairs", r.same_instant_pairs},
                   {"thresholds_px", r.options.thresholds_px},
                   {"localisation_threshold_px", r.options.localisation_px},
                   {"baseline_edges_m", r.options.baseline_edges_m},
                   {"depth_tolerance", {{"abs_m", r.options.correspondence.depth_abs_m},
                                        {"rel", r.options.correspondence.depth_rel}}}};
  j["conditions"] = nlohmann::json::array();
  for (const auto& c : r.conditions) j["conditions"].push_back({{"name", c.name}, {"dataset", c.dataset}});
  j["limit"] = nullptr;
  if (r.duration_s) j["limit"] = {{"duration_s", *r.duration_s}};
  if (r.frames) j["limit"] = {{"frames", *r.frames}};
  j["matcher"] = nullptr;
  if (r.matcher)
    j["matcher"] = {{"ratio", r.matcher->ratio}, {"mutual", r.matcher->mutual}, {"max_features", r.matcher->max_features}};
  j["methods"] = nlohmann::json::array();
  for (const auto& m : r.methods) {
    nlohmann::json jm{{"name", m.name},
                      {"detect_ms_per_frame", jnum(m.detect_ms_per_frame)},
                      {"detect_cpu_ms_per_frame", jnum(m.detect_cpu_ms_per_frame)},
                      {"keypoints_per_frame", jnum(m.keypoints_per_frame)}};
    jm["groups"] = nlohmann::json::array();
    for (const auto& g : m.groups) jm["groups"].push_back(group_json(g, r.options));
    j["methods"].push_back(jm);
  }
  return j.dump(2) + "\n";
}

std::string scores_csv(const MatchReport& r) {
  std::string s =
      "method,condition,type,baseline,pairs,keypoints_a,covisible,matches,detect_ms_per_frame,detect_cpu_ms_per_frame,"
      "localisation_px";
  for (double t : r.options.thresholds_px)
    s += fmt::format(",repeatability_{0:g}px,precision_{0:g}px,recall_{0:g}px", t);
  s += "\n";
  for (const auto& m : r.methods)
    for (const auto& g : m.groups) {
      const MatchCounts& c = g.counts;
      s += fmt::format("{},{},{},{},{},{},{},{},{},{},{}", m.name, g.condition, g.type, g.baseline, c.pairs,
                       c.keypoints_a, c.covisible, c.matches, num(m.detect_ms_per_frame, 3),
                       num(m.detect_cpu_ms_per_frame, 3), num(c.localisation_px(), 4));
      for (std::size_t t = 0; t < r.options.thresholds_px.size(); ++t)
        s += fmt::format(",{},{},{}", num(c.repeatability(t), 6), num(c.precision(t), 6), num(c.recall(t), 6));
      s += "\n";
    }
  return s;
}

std::string curves_csv(const MatchReport& r) {
  std::string s = "method,condition,type,baseline,threshold_px,repeatability,precision,recall\n";
  for (const auto& m : r.methods)
    for (const auto& g : m.groups)
      for (std::size_t t = 0; t < r.options.thresholds_px.size(); ++t)
        s += fmt::format("{},{},{},{},{:g},{},{},{}\n", m.name, g.condition, g.type, g.baseline,
                         r.options.thresholds_px[t], num(g.counts.repeatability(t), 6),
                         num(g.counts.precision(t), 6), num(g.counts.recall(t), 6));
  return s;
}

// Each method's scores per pair type and condition (all baselines) at the localisation threshold,
// one line of plots/conditions.png per method and type: rows in that order, conditions numbered
// as the report lists them (0 the reference).
std::string conditions_csv(const MatchReport& r) {
  const std::size_t k = main_column(r.options);
  std::vector<std::string> names{kReference};
  for (const auto& c : r.conditions) names.push_back(c.name);
  std::string s = "method,type,condition_index,condition,pairs,threshold_px,precision,recall,repeatability\n";
  for (const auto& m : r.methods)
    for (const PairType type : kPairTypes)
      for (std::size_t i = 0; i < names.size(); ++i)
        for (const auto& g : m.groups)
          if (g.condition == names[i] && g.type == to_string(type) && g.baseline == "all")
            s += fmt::format("{},{},{},{},{},{:g},{},{},{}\n", m.name, g.type, i, g.condition, g.counts.pairs,
                             r.options.thresholds_px[k], num(g.counts.precision(k), 6), num(g.counts.recall(k), 6),
                             num(g.counts.repeatability(k), 6));
  return s;
}

}  // namespace

MatchReport make_report(const std::string& dataset, const Conditions& sets, const std::vector<FramePair>& pairs,
                        const ScoreOptions& options) {
  MatchReport r;
  r.dataset = dataset;
  for (const auto& c : sets.conditions()) r.conditions.push_back({c.name, c.dataset.root.string()});
  r.pairs = pairs.size();
  for (const auto& p : pairs)
    (p.type == PairType::Temporal ? r.temporal_pairs : p.type == PairType::Cross ? r.cross_pairs : r.same_instant_pairs)++;
  r.options = options;
  return r;
}

std::string describe_pairs(const MatchReport& r) {
  std::string s = fmt::format("{} pairs ({} temporal, {} cross-UAV", r.pairs, r.temporal_pairs, r.cross_pairs);
  if (r.same_instant_pairs > 0) s += fmt::format(", {} same-instant", r.same_instant_pairs);
  s += ")";
  if (r.conditions.empty()) return s;
  std::vector<std::string> names;
  for (const auto& c : r.conditions) names.push_back(c.name);
  return s + fmt::format(" over {} conditions besides the reference ({})", r.conditions.size(), fmt::join(names, ", "));
}

std::string format_match_table(const MatchReport& r) {
  const auto cols = table_columns(r.options);
  const std::size_t k = main_column(r.options);
  const double eps = r.options.thresholds_px[k];
  const bool conditions = !r.conditions.empty();
  const int type_width = conditions ? 12 : 9;  // "same-instant" comes with conditions only
  std::string s = fmt::format("{:<10} ", "method");
  if (conditions) s += fmt::format("{:<12} ", "condition");
  s += fmt::format("{:<{}} {:<14} {:>5} {:>7} {:>8} {:>6}", "pairs", type_width, "baseline", "n", "kp/frm",
                   "match/pr", fmt::format("rep{:g}", eps));
  for (auto t : cols) s += fmt::format(" {:>6}", fmt::format("P@{:g}", r.options.thresholds_px[t]));
  for (auto t : cols) s += fmt::format(" {:>6}", fmt::format("R@{:g}", r.options.thresholds_px[t]));
  s += fmt::format(" {:>7} {:>7} {:>7}\n", "loc px", "ms/frm", "cpu/frm");
  for (const auto& m : r.methods)
    for (const auto& g : m.groups) {
      const MatchCounts& c = g.counts;
      s += fmt::format("{:<10} ", m.name);
      if (conditions) s += fmt::format("{:<12} ", g.condition);
      s += fmt::format("{:<{}} {:<14} {:>5} {:>7} {:>8} {:>6}", g.type, type_width, g.baseline, c.pairs,
                       num(per(c.keypoints_a + c.keypoints_b, 2 * c.pairs), 0), num(per(c.matches, c.pairs), 1),
                       pct(c.repeatability(k)));
      for (auto t : cols) s += fmt::format(" {:>6}", pct(c.precision(t)));
      for (auto t : cols) s += fmt::format(" {:>6}", pct(c.recall(t)));
      const bool all = &g == &m.groups.front();  // the times are per method
      s += fmt::format(" {:>7} {:>7} {:>7}\n", num(c.localisation_px(), 2),
                       all ? num(m.detect_ms_per_frame, 1) : "", all ? num(m.detect_cpu_ms_per_frame, 1) : "");
    }
  s += fmt::format(
      "n: pairs; kp/frm: keypoints per frame; rep{0:g}: % of A's keypoints visible in B with a keypoint of B "
      "within {0:g} px of their true correspondence; P@e / R@e: % of matches within e px of the truth / "
      "% of the repeatable A keypoints matched correctly; loc px: mean error of the matches within "
      "{0:g} px; ms/frm, cpu/frm: detection + description per frame, wall and process CPU time\n",
      eps);
  return s;
}

void write_match_report(const MatchReport& r, const fs::path& dir, bool plots) {
  io::write_file_atomic(dir / "scores.json", scores_json(r));
  io::write_file_atomic(dir / "scores.csv", scores_csv(r));
  io::write_file_atomic(dir / "curves.csv", curves_csv(r));
  if (!r.conditions.empty()) io::write_file_atomic(dir / "conditions.csv", conditions_csv(r));
  if (!plots) return;
  std::vector<std::string> names;
  for (const auto& m : r.methods) names.push_back(m.name);
  eval::plot_match_curves(names, dir);
  if (r.conditions.empty()) return;
  std::vector<std::string> conditions{kReference};
  for (const auto& c : r.conditions) conditions.push_back(c.name);
  eval::plot_conditions(names, conditions, r.options.thresholds_px[main_column(r.options)], dir);
}

}  // namespace wingman::frontend_bench
