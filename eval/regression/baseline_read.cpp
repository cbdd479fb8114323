// Reading a baseline file: every complaint names the file, the line and the key.
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>
#include <set>

#include "eval/regression/baseline.hpp"
#include "eval/output/writers.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;

class Reader {
 public:
  explicit Reader(fs::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    const int line = at.Mark().line >= 0 ? at.Mark().line + 1 : 0;
    throw CheckInputError(fmt::format("{}:{}: {}", file_.string(), line, what));
  }

  double number(const YAML::Node& n, const std::string& key, const std::string& where) const {
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(n, fmt::format("{}'{}' must be a finite number, got '{}'", where, key, n.IsScalar() ? n.Scalar() : "a collection"));
    return v;
  }

  std::string word(const YAML::Node& n, const std::string& key, const std::string& where,
                   const std::set<std::string>& allowed) const {
    if (!n.IsScalar() || !allowed.count(n.Scalar())) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(n, fmt::format("{}'{}' must be one of {}, got '{}'", where, key, list, n.IsScalar() ? n.Scalar() : "a collection"));
    }
    return n.Scalar();
  }

  // yaml-cpp keeps one of two equal keys silently; a baseline must not.
  void unique_keys(const YAML::Node& map, const std::string& where) const {
    std::map<std::string, int> seen;
    for (const auto& kv : map) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
      if (auto [it, added] = seen.emplace(key, kv.first.Mark().line + 1); !added)
        fail(kv.first, fmt::format("{}duplicate key '{}' (first at line {})", where, key, it->second));
    }
  }

  BaselineEntry entry(const YAML::Node& m, std::size_t index) const;
  void header(const YAML::Node& root, Baseline& b) const;

 private:
  fs::path file_;
};

Rule parse_rule(const std::string& s) {
  if (s == "max") return Rule::kMax;
  if (s == "min") return Rule::kMin;
  if (s == "rel") return Rule::kRel;
  if (s == "abs") return Rule::kAbs;
  if (s == "mean") return Rule::kMean;
  return Rule::kPaired;
}

BaselineEntry Reader::entry(const YAML::Node& m, std::size_t index) const {
  static const std::set<std::string> keys = {"metric", "reference", "rule", "tolerance", "limit", "better",
                                             "on_breach", "std", "n", "per_seed"};
  if (!m.IsMap()) fail(m, fmt::format("metrics[{}] must be a mapping with metric, reference, rule, ...", index));
  if (!m["metric"] || !m["metric"].IsScalar() || m["metric"].Scalar().empty())
    fail(m, fmt::format("metrics[{}]: 'metric' (a metric path) is missing", index));
  BaselineEntry e;
  e.metric = m["metric"].Scalar();
  e.line = m.Mark().line + 1;
  const std::string where = fmt::format("metric {}: ", e.metric);
  unique_keys(m, where);
  for (const auto& kv : m)
    if (!keys.count(kv.first.Scalar()))
      fail(kv.first, fmt::format("{}unknown key '{}' (known: metric, reference, rule, tolerance, limit, better, "
                                 "on_breach, std, n, per_seed)", where, kv.first.Scalar()));
  for (const char* k : {"reference", "rule"})
    if (!m[k]) fail(m, fmt::format("{}'{}' is missing", where, k));
  e.reference = number(m["reference"], "reference", where);
  e.rule = parse_rule(word(m["rule"], "rule", where, {"max", "min", "rel", "abs", "mean", "paired"}));
  const bool bound = e.rule == Rule::kMax || e.rule == Rule::kMin;
  const char* needed = bound ? "limit" : "tolerance";
  if (!m[needed]) fail(m, fmt::format("{}rule {} needs '{}'", where, rule_name(e.rule), needed));
  if (bound) e.limit = number(m["limit"], "limit", where);
  else if ((e.tolerance = number(m["tolerance"], "tolerance", where)) < 0)
    fail(m["tolerance"], fmt::format("{}'tolerance' must be >= 0, got {}", where, e.tolerance));
  if (m["better"]) {
    const auto b = word(m["better"], "better", where, {"lower", "higher", "either"});
    e.better = b == "lower" ? Better::kLower : b == "higher" ? Better::kHigher : Better::kEither;
  }
  if (m["on_breach"]) e.warn_only = word(m["on_breach"], "on_breach", where, {"fail", "warn"}) == "warn";
  if (m["std"] && (e.std = number(m["std"], "std", where)) < 0)
    fail(m["std"], fmt::format("{}'std' must be >= 0", where));
  if (m["n"] && (e.n = static_cast<int>(number(m["n"], "n", where))) < 1) fail(m["n"], fmt::format("{}'n' must be >= 1", where));
  if (m["per_seed"]) {
    if (!m["per_seed"].IsMap()) fail(m["per_seed"], fmt::format("{}'per_seed' must be a mapping seed: value", where));
    for (const auto& kv : m["per_seed"]) {
      std::uint64_t seed = 0;
      if (!YAML::convert<std::uint64_t>::decode(kv.first, seed))
        fail(kv.first, fmt::format("{}per_seed: '{}' is not a seed", where, kv.first.Scalar()));
      e.per_seed[seed] = number(kv.second, "per_seed", where);
    }
  }
  if (e.rule == Rule::kPaired && e.per_seed.size() < 2)
    fail(m, fmt::format("{}rule paired needs 'per_seed' with at least two seeds", where));
  return e;
}

void Reader::header(const YAML::Node& root, Baseline& b) const {
  if (!root.IsMap()) fail(root, "a baseline is a mapping with baseline_schema, metrics_schema and metrics");
  unique_keys(root, "");
  for (const char* k : {"baseline_schema", "metrics_schema", "metrics"})
    if (!root[k]) fail(root, fmt::format("'{}' is missing", k));
  if (number(root["baseline_schema"], "baseline_schema", "") != kBaselineSchemaVersion)
    fail(root["baseline_schema"], fmt::format("baseline_schema {}, this wingman reads {}",
                                               root["baseline_schema"].Scalar(), kBaselineSchemaVersion));
  b.metrics_schema = static_cast<int>(number(root["metrics_schema"], "metrics_schema", ""));
  if (b.metrics_schema != kMetricsSchemaVersion)
    fail(root["metrics_schema"], fmt::format("made from metrics schema {}, this wingman writes schema {}: "
                                             "make the baseline again (wingman baseline)", b.metrics_schema,
                                             kMetricsSchemaVersion));
  for (const auto& kv : root)
    if (!std::set<std::string>{"baseline_schema", "metrics_schema", "source", "metrics"}.count(kv.first.Scalar()))
      fail(kv.first, fmt::format("unknown key '{}' (known: baseline_schema, metrics_schema, source, metrics)",
                                 kv.first.Scalar()));
  if (const YAML::Node src = root["source"]; src && src.IsMap()) {
    unique_keys(src, "source: ");
    for (const auto& kv : src)
      if (!std::set<std::string>{"kind", "scenario", "software_version", "seeds"}.count(kv.first.Scalar()))
        fail(kv.first, fmt::format("source: unknown key '{}' (known: kind, scenario, software_version, seeds)",
                                   kv.first.Scalar()));
    if (src["kind"]) b.kind = word(src["kind"], "kind", "source: ", {"results", "montecarlo"});
    if (src["scenario"] && src["scenario"].IsScalar()) b.scenario = src["scenario"].Scalar();
    if (src["software_version"] && src["software_version"].IsScalar()) b.software_version = src["software_version"].Scalar();
  }
  if (!root["metrics"].IsSequence() || root["metrics"].size() == 0)
    fail(root["metrics"], "'metrics' must be a non-empty list");
}

}  // namespace

Baseline read_baseline(const fs::path& file) {
  Baseline b;
  b.file = file;
  if (!fs::is_regular_file(file)) throw CheckInputError(fmt::format("{}: no such file", file.string()));
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw CheckInputError(fmt::format("{}:{}: not valid YAML: {}", file.string(), e.mark.line + 1, e.msg));
  }
  const Reader r(file);
  r.header(root, b);
  std::set<std::string> seen;
  for (std::size_t i = 0; i < root["metrics"].size(); ++i) {
    BaselineEntry e = r.entry(root["metrics"][i], i);
    if (!seen.insert(e.metric).second)
      r.fail(root["metrics"][i], fmt::format("metric {} is listed twice", e.metric));
    b.entries.push_back(std::move(e));
  }
  return b;
}

}  // namespace wingman::eval
