// A baseline: the reference value of each chosen metric and the rule `wingman check` judges it
// by, kept as plain YAML a person edits and commits (docs/check.md has the format).
//
//   baseline_schema: 1
//   metrics_schema: 2
//   source: {kind: results, dir: results/smoke, scenario: smoke, seeds: [1], software_version: 0.9.0}
//   metrics:
//     - metric: multi/table4.total.lead.mse.x
//       reference: 0.0123
//       rule: rel          # max | min | rel | abs | mean | paired
//       tolerance: 0.25    # rel, mean, paired: a fraction of the reference; abs: in its unit
//       better: lower      # lower | higher | either: which change is a regression
//       on_breach: fail    # fail | warn
//       # max, min: `limit` instead of tolerance. Monte Carlo baselines add std, n and
//       # per_seed {seed: value}, which mean and paired use.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "eval/regression/metric_set.hpp"

namespace wingman::eval {

inline constexpr int kBaselineSchemaVersion = 1;

enum class Rule { kMax, kMin, kRel, kAbs, kMean, kPaired };
enum class Better { kLower, kHigher, kEither };

struct BaselineEntry {
  std::string metric;
  double reference = 0;
  Rule rule = Rule::kRel;
  double tolerance = 0;  // rel, abs, mean, paired
  double limit = 0;      // max, min
  Better better = Better::kLower;
  bool warn_only = false;  // on_breach: warn
  // Monte Carlo baselines: the seeds' spread and each seed's value.
  double std = 0;
  int n = 1;
  std::map<std::uint64_t, double> per_seed;
  int line = 0;  // in the baseline file, for messages
};

struct Baseline {
  std::filesystem::path file;
  int metrics_schema = 0;
  std::string kind;  // "results" or "montecarlo"
  std::string scenario, software_version;
  std::vector<std::uint64_t> seeds;
  std::vector<BaselineEntry> entries;
  std::vector<std::string> left_out;  // make_baseline: chosen metrics without a value (in some seed)
};

struct BaselineOptions {
  std::vector<std::string> metrics;  // globs; empty: default_metrics
  double rel = -1, abs = -1;         // tolerance of the relative / absolute rules; < 0: each metric's default
  // The rule of every metric whose default is relative (rel, mean or paired: errors, the NEES,
  // counts), e.g. mean for a Monte Carlo baseline that single runs or other seeds are checked
  // against; empty: the default.
  std::string rule;
};

const char* rule_name(Rule r);
const char* better_name(Better b);

// A baseline of `set`: each chosen metric with a finite value, with its default rule (Monte
// Carlo: paired; a results directory: rel, or abs for fractions and rates), direction and
// on_breach (warn for timings). CheckInputError when a glob matches nothing, or for a rule that
// the directory cannot give (mean or paired of a single run).
Baseline make_baseline(const MetricSet& set, const BaselineOptions& options);

// The YAML text of a baseline (every number written so that it reads back exactly).
std::string baseline_yaml(const Baseline& b);

// Reads a baseline file. CheckInputError naming the file, line and key for anything malformed:
// not YAML, another schema, an unknown rule, a negative tolerance, a metric listed twice.
Baseline read_baseline(const std::filesystem::path& file);

}  // namespace wingman::eval
