#include "eval/regression/metric_set.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fnmatch.h>

#include <algorithm>
#include <set>

#include "eval/output/json_file.hpp"
#include "eval/metrics/run_record.hpp"
#include "eval/output/writers.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Keys that are not metrics: identity, conventions, a failure's step and time, phase indices
// and bounds. Numeric series (per_step, count_per_step, per_phase_mean, histogram counts) need no
// entry: flatten_array keeps only the named vectors below.
const std::set<std::string> kSkippedKeys = {
    "schema_version", "conventions", "software_version", "scenario", "numerical_failure",
    "phase", "t_start", "t_end", "t_from", "config", "components"};

// Numeric arrays that are vectors with named components.
const char* const kXyz[] = {"x", "y", "z"};
const char* const kFormation[] = {"lambda_x", "lambda_y", "lambda_z", "psi"};

using Flat = std::vector<std::pair<std::string, double>>;

double number(const json& v) { return v.is_number() ? v.get<double>() : kNaN; }

void flatten(const json& j, const std::string& path, const std::string& key, Flat& out);

void flatten_array(const json& a, const std::string& path, const std::string& key, Flat& out) {
  const bool xyz = key == "mse" || key == "final_mse" || key == "init_mse";
  const bool formation = key == "rms" || key == "max_abs";
  if ((xyz && a.size() == 3) || (formation && a.size() == 4)) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i].is_number() || a[i].is_null()) out.emplace_back(path + "." + (xyz ? kXyz[i] : kFormation[i]), number(a[i]));
    return;
  }
  // Rows named by "name" (phases) or "channel" (Table 3) are keyed by it; other arrays are series.
  for (const json& row : a) {
    if (!row.is_object()) return;
    const char* name_key = row.contains("name") ? "name" : row.contains("channel") ? "channel" : nullptr;
    if (!name_key || !row[name_key].is_string()) return;
    flatten(row, path + "." + row[name_key].get<std::string>(), "", out);
  }
}

void flatten(const json& j, const std::string& path, const std::string& key, Flat& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items())
      if (!kSkippedKeys.count(k)) flatten(v, path.empty() ? k : path + "." + k, k, out);
  } else if (j.is_array()) {
    flatten_array(j, path, key, out);
  } else if (j.is_number() || (j.is_null() && !path.empty())) {
    out.emplace_back(path, number(j));
  }
}

// metrics.json of one run, its schema checked.
json read_metrics(const fs::path& file) {
  if (!fs::exists(file)) throw CheckInputError(fmt::format("{}: no such file", file.string()));
  json j;
  try {
    j = read_json_file(file);
  } catch (const std::runtime_error& e) {
    throw CheckInputError(e.what());
  }
  if (!j.is_object() || !j.contains("schema_version"))
    throw CheckInputError(fmt::format(
        "{}: no schema_version: written by a wingman older than metrics schema {}; rerun the "
        "scenario with this version", file.string(), kMetricsSchemaVersion));
  const json& v = j["schema_version"];
  if (!v.is_number_integer() || v.get<int>() != kMetricsSchemaVersion)
    throw CheckInputError(fmt::format("{}: metrics schema {}, this wingman reads schema {}", file.string(),
                                      v.dump(), kMetricsSchemaVersion));
  return j;
}

// Adds one run's metrics as seed index `s` of `n`; returns the run's seed.
std::uint64_t add_run(MetricSet& set, const fs::path& file, const std::string& prefix, std::size_t s, std::size_t n) {
  const json j = read_metrics(file);
  try {
    if (set.software_version.empty()) set.software_version = j.value("software_version", std::string());
    const json& scenario = j.at("scenario");
    if (set.scenario.empty()) set.scenario = scenario.at("name").get<std::string>();
    if (j.contains("numerical_failure") && j["numerical_failure"].is_object())
      set.failures.push_back(fmt::format("{}: {}", file.string(),
                                         j["numerical_failure"].value("message", std::string("numerical failure"))));
    Flat flat;
    flatten(j, "", "", flat);
    for (const auto& [path, value] : flat) {
      const std::string full = prefix + path;
      auto [it, added] = set.values.try_emplace(full, std::vector<double>(n, kNaN));
      if (added) set.paths.push_back(full);
      it->second[s] = value;
    }
    return scenario.at("seed").get<std::uint64_t>();
  } catch (const json::exception& e) {  // a file wingman wrote holds these keys with these types
    throw CheckInputError(fmt::format("{}: not a metrics.json of schema {}: {}", file.string(), kMetricsSchemaVersion,
                                      e.what()));
  }
}

// The variant subdirectories of a run directory that hold metrics.json (none: the run itself).
std::vector<std::string> variant_dirs(const fs::path& run) {
  std::vector<std::string> subs;
  if (fs::exists(run / "metrics.json")) return {""};
  for (const auto& e : fs::directory_iterator(run))
    if (e.is_directory() && fs::exists(e.path() / "metrics.json")) subs.push_back(e.path().filename().string());
  std::sort(subs.begin(), subs.end());
  return subs;
}

void read_results_dir(MetricSet& set) {
  const auto subs = variant_dirs(set.dir);
  if (subs.empty())
    throw CheckInputError(fmt::format("{}: not a results directory (no metrics.json in it or in a "
                                      "variant directory) nor a Monte Carlo directory (no montecarlo.json)",
                                      set.dir.string()));
  for (const auto& sub : subs) {
    const std::uint64_t seed = add_run(set, set.dir / sub / "metrics.json", sub.empty() ? "" : sub + "/", 0, 1);
    if (set.seeds.empty()) set.seeds = {seed};
  }
}

// montecarlo.json's aggregated and failed seeds.
void read_monte_carlo_seeds(MetricSet& set, const fs::path& file) {
  json mc;
  try {
    mc = read_json_file(file);
    for (const json& s : mc.at("seeds")) set.seeds.push_back(s.get<std::uint64_t>());
    for (const json& f : mc.value("failed_seeds", json::array()))
      set.failures.push_back(fmt::format("{}: seed {}: {}", file.string(), f.at("seed").get<std::uint64_t>(),
                                         f.value("reason", std::string("failed"))));
  } catch (const json::exception& e) {
    throw CheckInputError(fmt::format("{}: not a montecarlo.json of this wingman: {}", file.string(), e.what()));
  } catch (const std::runtime_error& e) {
    throw CheckInputError(e.what());
  }
  if (set.seeds.empty()) throw CheckInputError(fmt::format("{}: no seed was aggregated", file.string()));
}

void read_monte_carlo_dir(MetricSet& set) {
  read_monte_carlo_seeds(set, set.dir / "montecarlo.json");
  set.monte_carlo = true;
  const auto run = [&](std::uint64_t seed) { return set.dir / "runs" / fmt::format("seed{}", seed); };
  if (!fs::is_directory(run(set.seeds.front())))
    throw CheckInputError(fmt::format("{}: no such run directory", run(set.seeds.front()).string()));
  const auto subs = variant_dirs(run(set.seeds.front()));
  if (subs.empty()) throw CheckInputError(fmt::format("{}: holds no metrics.json", run(set.seeds.front()).string()));
  for (std::size_t s = 0; s < set.seeds.size(); ++s)
    for (const auto& sub : subs)
      add_run(set, run(set.seeds[s]) / sub / "metrics.json", sub.empty() ? "" : sub + "/", s, set.seeds.size());
}

}  // namespace

MetricSet read_metric_set(const fs::path& dir) {
  MetricSet set;
  set.dir = dir;
  if (!fs::is_directory(dir)) throw CheckInputError(fmt::format("{}: no such directory", dir.string()));
  if (fs::exists(dir / "montecarlo.json")) read_monte_carlo_dir(set);
  else read_results_dir(set);
  return set;
}

bool is_timing_metric(const std::string& path) {
  const auto key = path.substr(path.find('/') == std::string::npos ? 0 : path.find('/') + 1);
  return key == "wall_time_s" || key.rfind("timings_ms.", 0) == 0 || key.find("_ms_per_step") != std::string::npos ||
         key.rfind("frame_cache.", 0) == 0 ||  // the cache's use: how a run got its frames, not what it found
         key.rfind("frame_regions.", 0) == 0;
}

std::vector<std::string> default_metrics(const MetricSet& set) {
  static const std::vector<std::string> globs = {
      "table4.total.*.mse.*",         "table5.total.final_mse.*",      "table3.*.accepted_outlier_fraction",
      "nees.mean",                    "frontend.lead_detection_rate",  "frontend.lead_error_px.mean",
      "wall_time_s",                  "timings_ms.*.mean"};
  // Variant by variant (in the order they appear), then in the order of the globs.
  std::vector<std::string> prefixes;
  for (const auto& path : set.paths) {
    const auto slash = path.find('/');
    const std::string prefix = slash == std::string::npos ? "" : path.substr(0, slash + 1);
    if (std::find(prefixes.begin(), prefixes.end(), prefix) == prefixes.end()) prefixes.push_back(prefix);
  }
  std::vector<std::string> chosen;
  for (const auto& prefix : prefixes)
    for (const auto& g : globs)
      for (const auto& path : set.paths)
        if (path.rfind(prefix, 0) == 0 && path.find('/', prefix.size()) == std::string::npos &&
            fnmatch(g.c_str(), path.c_str() + prefix.size(), 0) == 0)
          chosen.push_back(path);
  return chosen;
}

std::vector<std::string> select_metrics(const MetricSet& set, const std::vector<std::string>& globs) {
  std::vector<std::string> chosen;
  for (const auto& g : globs) {
    const auto matches = [&](const std::string& p) { return fnmatch(g.c_str(), p.c_str(), 0) == 0; };
    if (std::none_of(set.paths.begin(), set.paths.end(), matches)) {
      std::vector<std::string> some(set.paths.begin(), set.paths.begin() + std::min<std::size_t>(set.paths.size(), 6));
      throw CheckInputError(fmt::format("--metrics '{}': matches no metric of {} (they read like: {}, ...)", g,
                                        set.dir.string(), fmt::join(some, ", ")));
    }
  }
  // In the order of the globs, each metric once.
  std::set<std::string> seen;
  for (const auto& g : globs)
    for (const auto& p : set.paths)
      if (fnmatch(g.c_str(), p.c_str(), 0) == 0 && seen.insert(p).second) chosen.push_back(p);
  return chosen;
}

}  // namespace wingman::eval
