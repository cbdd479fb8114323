#include "eval/regression/baseline.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <optional>
#include <set>

#include "eval/stats/montecarlo.hpp"
#include "eval/output/writers.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;

struct Default {
  Rule rule;
  double tolerance;
  Better better;
  bool warn_only;
};

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// Errors of an estimate against the truth: lower is better.
bool is_error_metric(const std::string& m) {
  for (const char* part : {".mse.", "final_mse.", "init_mse.", "rms_error", "max_error", "_px.", ".rms.", ".max_abs.",
                           "settling_time"})
    if (m.find(part) != std::string::npos) return true;
  return false;
}

// Fractions and rates have an absolute tolerance (a relative one around 0 means nothing);
// timings warn (machines differ); errors are lower-is-better; anything else (the NEES, counts)
// is wrong on either side.
Default default_rule(const std::string& metric, bool monte_carlo) {
  if (is_timing_metric(metric)) return {monte_carlo ? Rule::kMean : Rule::kRel, 1.0, Better::kLower, true};
  if (ends_with(metric, "_fraction")) return {Rule::kAbs, 0.02, Better::kLower, false};
  if (ends_with(metric, "_rate")) return {Rule::kAbs, 0.05, Better::kHigher, false};
  const Better better = is_error_metric(metric) ? Better::kLower : Better::kEither;
  return monte_carlo ? Default{Rule::kPaired, 0.10, better, false} : Default{Rule::kRel, 0.25, better, false};
}

// Shortest text that reads back to the same double.
std::string num(double v) { return fmt::format("{}", v); }

// The relative rule --rule names; CheckInputError for one the directory cannot give.
Rule chosen_rule(const std::string& name, bool monte_carlo) {
  if (name == "rel") return Rule::kRel;
  if (name != "mean" && name != "paired")
    throw CheckInputError(fmt::format("--rule {}: must be rel, mean or paired", name));
  if (!monte_carlo)
    throw CheckInputError(fmt::format("--rule {}: needs a Monte Carlo directory (the seeds' spread)", name));
  return name == "mean" ? Rule::kMean : Rule::kPaired;
}

}  // namespace

const char* rule_name(Rule r) {
  switch (r) {
    case Rule::kMax: return "max";
    case Rule::kMin: return "min";
    case Rule::kRel: return "rel";
    case Rule::kAbs: return "abs";
    case Rule::kMean: return "mean";
    case Rule::kPaired: return "paired";
  }
  return "?";
}

const char* better_name(Better b) {
  switch (b) {
    case Better::kLower: return "lower";
    case Better::kHigher: return "higher";
    case Better::kEither: return "either";
  }
  return "?";
}

Baseline make_baseline(const MetricSet& set, const BaselineOptions& o) {
  // A plain flag and value (not std::optional): GCC 12 warns falsely of an uninitialised optional.
  const bool override_rule = !o.rule.empty();
  const Rule relative_rule = override_rule ? chosen_rule(o.rule, set.monte_carlo) : Rule::kRel;
  Baseline b;
  b.metrics_schema = kMetricsSchemaVersion;
  b.kind = set.monte_carlo ? "montecarlo" : "results";
  b.scenario = set.scenario;
  b.software_version = set.software_version;
  b.seeds = set.seeds;
  const auto chosen = o.metrics.empty() ? default_metrics(set) : select_metrics(set, o.metrics);
  for (const auto& metric : chosen) {
    const std::vector<double>& v = set.values.at(metric);
    const Spread s = spread_of(v);
    if (s.n != static_cast<int>(v.size()) || s.n == 0) {  // a value missing: nothing to hold it to
      b.left_out.push_back(metric);
      continue;
    }
    const Default d = default_rule(metric, set.monte_carlo);
    BaselineEntry e;
    e.metric = metric;
    e.reference = s.mean;
    const bool relative = d.rule == Rule::kRel || d.rule == Rule::kMean || d.rule == Rule::kPaired;
    e.rule = relative && !d.warn_only && override_rule ? relative_rule : d.rule;
    e.better = d.better;
    e.warn_only = d.warn_only;
    e.tolerance = d.tolerance;
    if (!d.warn_only && d.rule == Rule::kAbs && o.abs >= 0) e.tolerance = o.abs;
    if (!d.warn_only && d.rule != Rule::kAbs && o.rel >= 0) e.tolerance = o.rel;
    if (set.monte_carlo) {
      e.std = s.n > 1 ? s.std : 0;
      e.n = s.n;
      for (std::size_t i = 0; i < v.size(); ++i) e.per_seed[set.seeds[i]] = v[i];
    }
    b.entries.push_back(std::move(e));
  }
  return b;
}

std::string baseline_yaml(const Baseline& b) {
  std::string s = fmt::format(
      "# wingman baseline of {} ({}), made by `wingman baseline`; `wingman check <dir> --baseline "
      "<this file>` judges\n# a results directory against it. Edit rule, tolerance, better and "
      "on_breach as you see fit (docs/check.md).\n"
      "baseline_schema: {}\nmetrics_schema: {}\n"
      "source: {{kind: {}, scenario: \"{}\", software_version: \"{}\", seeds: [{}]}}\nmetrics:\n",
      b.scenario, b.kind, kBaselineSchemaVersion, b.metrics_schema, b.kind, b.scenario, b.software_version,
      fmt::join(b.seeds, ", "));
  for (const BaselineEntry& e : b.entries) {
    s += fmt::format("  - metric: \"{}\"\n    reference: {}\n    rule: {}\n", e.metric, num(e.reference),
                     rule_name(e.rule));
    if (e.rule == Rule::kMax || e.rule == Rule::kMin) s += fmt::format("    limit: {}\n", num(e.limit));
    else s += fmt::format("    tolerance: {}\n", num(e.tolerance));
    s += fmt::format("    better: {}\n    on_breach: {}\n", better_name(e.better), e.warn_only ? "warn" : "fail");
    if (!e.per_seed.empty()) {
      s += fmt::format("    std: {}\n    n: {}\n    per_seed: {{", num(e.std), e.n);
      bool first = true;
      for (const auto& [seed, v] : e.per_seed) s += fmt::format("{}{}: {}", first ? "" : ", ", seed, num(v)), first = false;
      s += "}\n";
    }
  }
  return s;
}

}  // namespace wingman::eval
