// `wingman observability`: the observability analysis of paper section 4 (docs/design.md, the estimator) for a
// sensor set (a Table 1 preset or an explicit list), at a generic seeded state or at the state of
// a scenario's trajectory; prints dim(x), the rank, the unobservable modes and per-state verdicts.
#include "app/cli/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/cli/cli_options.hpp"
#include "app/config/run_config.hpp"
#include "app/pipeline/observability_point.hpp"
#include "slam/observability.hpp"

namespace wingman::app {

namespace {

struct ObsOptions {
  std::optional<int> config;
  std::optional<std::string> sees_lead, altimeter, range, visibility;
  bool gps = false;
  CLI::Option* gps_opt = nullptr;
  std::optional<int> uavs;
  int landmarks = 6;
  int order = 1;
  unsigned long seed = 1;
  double tol = 1e-8;
  double state_tol = 1e-6;
  std::string scenario;
  std::vector<std::string> variants;
  double at = 0;
  CLI::Option* at_opt = nullptr;
  bool json = false;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else if (c != ' ') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

int parse_int(const std::string& s, const std::string& flag) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(s, &used);
    if (used == s.size()) return v;
  } catch (const std::exception&) {
  }
  throw io::UsageError(fmt::format("{}: '{}' is not an integer", flag, s));
}

// "uav2" -> 1, checked against the UAV count.
int uav_index(const std::string& name, int n2, const std::string& flag) {
  if (name.rfind("uav", 0) != 0 || name.size() == 3)
    throw io::UsageError(fmt::format("{}: '{}' is not a UAV name (uav1 .. uav{})", flag, name, n2));
  const int j = parse_int(name.substr(3), flag);
  if (j < 1 || j > n2)
    throw io::UsageError(fmt::format("{}: no {} (there are {} UAVs: uav1 .. uav{})", flag, name, n2, n2));
  return j - 1;
}

// "uav1,uav2" (or "none") -> per-UAV flags.
std::vector<bool> parse_uav_list(const std::string& list, int n2, const std::string& flag) {
  std::vector<bool> on(static_cast<std::size_t>(n2), false);
  if (list == "none" || list.empty()) return on;
  for (const auto& name : split(list, ',')) on[static_cast<std::size_t>(uav_index(name, n2, flag))] = true;
  return on;
}

// "uav1:0-3,5,uav2:2-5": after "uavN:", indices and ranges until the next UAV; "all" for every
// landmark. UAVs not listed see none.
std::vector<std::vector<int>> parse_visibility(const std::string& spec, int n2, int n1) {
  const std::string flag = "--visibility";
  std::vector<std::vector<int>> vis(static_cast<std::size_t>(n2));
  int current = -1;
  for (auto item : split(spec, ',')) {
    if (const auto colon = item.find(':'); colon != std::string::npos) {
      current = uav_index(item.substr(0, colon), n2, flag);
      item = item.substr(colon + 1);
    }
    if (item.empty()) continue;
    if (current < 0)
      throw io::UsageError(fmt::format("{}: '{}' comes before any 'uavN:' (e.g. uav1:0-3,uav2:2-5)", flag, item));
    auto& v = vis[static_cast<std::size_t>(current)];
    int lo = 0, hi = n1 - 1;
    if (item != "all") {
      const auto dash = item.find('-');
      lo = parse_int(item.substr(0, dash), flag);
      hi = dash == std::string::npos ? lo : parse_int(item.substr(dash + 1), flag);
      if (lo < 0 || hi >= n1 || lo > hi)
        throw io::UsageError(fmt::format("{}: landmarks '{}' outside 0..{}", flag, item, n1 - 1));
    }
    for (int i = lo; i <= hi; ++i)
      if (std::find(v.begin(), v.end(), i) == v.end()) v.push_back(i);
  }
  return vis;
}

std::string describe_uavs(const std::vector<bool>& on) {
  std::vector<std::string> names;
  for (std::size_t j = 0; j < on.size(); ++j)
    if (on[j]) names.push_back(fmt::format("uav{}", j + 1));
  return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ","));
}

std::string describe_visibility(const std::vector<std::vector<int>>& vis) {
  std::vector<std::string> parts;
  for (std::size_t j = 0; j < vis.size(); ++j) {
    std::vector<int> v = vis[j];
    std::sort(v.begin(), v.end());
    std::string s = fmt::format("uav{}:", j + 1);
    for (std::size_t a = 0; a < v.size();) {  // runs of consecutive indices as ranges
      std::size_t b = a;
      while (b + 1 < v.size() && v[b + 1] == v[b] + 1) ++b;
      s += fmt::format("{}{}", a ? "," : "", b > a ? fmt::format("{}-{}", v[a], v[b]) : fmt::format("{}", v[a]));
      a = b + 1;
    }
    parts.push_back(v.empty() ? s + "none" : s);
  }
  return fmt::format("{}", fmt::join(parts, " "));
}

std::string fmt_num(double v) { return std::fabs(v) < 5e-5 ? "0" : fmt::format("{:.4f}", v); }

int observability_command(const ObsOptions& o, const std::string& variant) {
  if (o.landmarks < 0) throw io::UsageError("--landmarks: must be >= 0");
  if (o.order < 0 || o.order > slam::kMaxLieOrder)
    throw io::UsageError(fmt::format("--order: must be in 0..{}", slam::kMaxLieOrder));
  if (!(o.tol > 0 && o.tol < 1)) throw io::UsageError("--tol: must be in (0, 1)");
  if (!(o.state_tol > 0 && o.state_tol < 1)) throw io::UsageError("--state-tol: must be in (0, 1)");
  if (o.config && (*o.config < 1 || *o.config > 3)) throw io::UsageError("--config: must be 1, 2 or 3");
  if (o.scenario.empty() && (o.at_opt->count() > 0 || !variant.empty()))
    throw io::UsageError("--at and --variant need --scenario");

  // Where to evaluate, and the sensor set to start from.
  slam::EvaluationPoint point;
  std::optional<slam::SensorSet> base;
  std::string where;
  const int n1 = o.landmarks;
  if (!o.scenario.empty()) {
    auto scenarios = load_run_configs(o.scenario);
    auto it = std::find_if(scenarios.begin(), scenarios.end(), [&](const RunConfig& s) {
      return variant.empty() || s.variant == variant;
    });
    if (it == scenarios.end()) throw io::UsageError(fmt::format("{}: no variant '{}'", o.scenario, variant));
    const RunConfig& scn = *it;
    if (!(o.at >= 0 && o.at <= scn.duration))
      throw io::UsageError(fmt::format("--at: {} outside the scenario's [0, {}] s", o.at, scn.duration));
    if (o.uavs && *o.uavs != static_cast<int>(scn.uavs.size()))
      throw io::UsageError(fmt::format("--uavs: the scenario has {} UAVs", scn.uavs.size()));
    point = scenario_point(scn, o.at, n1);
    base = scenario_sensors(scn, o.at, n1);
    where = fmt::format("scenario {}{} at t = {} s", scn.name, scn.variant.empty() ? "" : "/" + scn.variant, o.at);
  } else {
    const int n2 = o.uavs.value_or(2);
    if (n2 < 1) throw io::UsageError("--uavs: must be >= 1");
    point = slam::generic_point(n2, n1, o.seed);
    where = fmt::format("generic state (seed {})", o.seed);
  }
  const int n2 = point.state.num_cameras();

  // The preset, then explicit flags on top of it.
  slam::SensorSet s = o.config ? preset(*o.config, n2, n1) : base.value_or(slam::SensorSet::empty(n2, n1));
  if (o.sees_lead) s.sees_lead = parse_uav_list(*o.sees_lead, n2, "--sees-lead");
  if (o.altimeter) s.altimeter = parse_uav_list(*o.altimeter, n2, "--altimeter");
  if (o.range) s.range = parse_uav_list(*o.range, n2, "--range");
  if (o.visibility) s.visibility = parse_visibility(*o.visibility, n2, n1);
  if (o.gps_opt->count() > 0) s.gps = o.gps;

  slam::ObservabilityMatrix om;
  try {
    om = slam::observability_matrix(point, s, o.order);
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  const std::vector<std::string> names = slam::state_names(point.state);
  const slam::ObservabilityReport r = slam::analyse(om, names, o.tol, o.state_tol);
  std::vector<int> pivots;
  const Eigen::MatrixXd B = slam::readable_basis(r.null_space, &pivots);
  const auto& sv = r.singular_values;
  // How clearly the rank stands out: the last kept over the first dropped singular value.
  const double gap = (r.rank > 0 && r.rank < sv.size()) ? sv(r.rank - 1) / std::max(sv(r.rank), 1e-300) : INFINITY;
  std::vector<std::string> unobservable;
  for (int i = 0; i < r.dim; ++i)
    if (!r.observable[static_cast<std::size_t>(i)]) unobservable.push_back(names[static_cast<std::size_t>(i)]);

  if (o.json) {
    nlohmann::json j;
    j["dim"] = r.dim;
    j["rank"] = r.rank;
    j["unobservable_modes"] = r.unobservable_modes();
    j["lie_order"] = o.order;
    j["tolerance"] = r.tolerance;
    j["state_tolerance"] = r.state_tolerance;
    j["derivative_error"] = om.derivative_error;
    j["rank_gap"] = std::isfinite(gap) ? nlohmann::json(gap) : nlohmann::json(nullptr);
    j["evaluated_at"] = where;
    j["sensors"] = {{"visibility", describe_visibility(s.visibility)},
                    {"sees_lead", describe_uavs(s.sees_lead)},
                    {"altimeter", describe_uavs(s.altimeter)},
                    {"range", describe_uavs(s.range)},
                    {"gps", s.gps}};
    j["states"] = names;
    j["singular_values"] = std::vector<double>(sv.data(), sv.data() + sv.size());
    nlohmann::json modes = nlohmann::json::array();
    for (Eigen::Index c = 0; c < B.cols(); ++c) {
      nlohmann::json m;
      m["pivot"] = names[static_cast<std::size_t>(pivots[static_cast<std::size_t>(c)])];
      m["vector"] = std::vector<double>(B.col(c).data(), B.col(c).data() + B.rows());
      modes.push_back(m);
    }
    j["null_space"] = modes;
    nlohmann::json obs;
    for (int i = 0; i < r.dim; ++i) obs[names[static_cast<std::size_t>(i)]] = static_cast<bool>(r.observable[static_cast<std::size_t>(i)]);
    j["observable"] = obs;
    j["unobservable_states"] = unobservable;
    fmt::print("{}\n", j.dump(2));
    return 0;
  }

  fmt::print("observability: {} UAVs, {} landmarks, Lie derivatives of order 0..{}, {}\n", n2, n1, o.order, where);
  fmt::print("sensors: landmarks {}; lead seen by {}; altimeter {}; range {}; GPS {}\n",
             describe_visibility(s.visibility), describe_uavs(s.sees_lead), describe_uavs(s.altimeter),
             describe_uavs(s.range), s.gps ? "yes" : "no");
  fmt::print("dim(x) = {}, rank = {}, unobservable modes = {}\n", r.dim, r.rank, r.unobservable_modes());
  fmt::print("rank: singular values > {:g} x the largest; gap at the rank {}; finite-difference "
             "error ~{:.1e} (relative)\n",
             r.tolerance, std::isfinite(gap) ? fmt::format("{:.1e}", gap) : std::string("none (no mode or no rank)"),
             om.derivative_error);
  std::vector<std::string> svs;
  for (Eigen::Index i = 0; i < sv.size(); ++i) svs.push_back(fmt::format("{:.3g}", sv(i) / sv(0)));
  if (sv.size()) fmt::print("singular values / largest: {}\n", fmt::join(svs, " "));
  if (B.cols() > 0) {
    fmt::print("null space basis (each mode is 1 at its pivot state, 0 at the others' pivots):\n");
    fmt::print("  {:<10}", "state");
    for (Eigen::Index c = 0; c < B.cols(); ++c) fmt::print(" {:>9}", fmt::format("mode{}", c + 1));
    fmt::print("\n");
    for (int i = 0; i < r.dim; ++i) {
      if (B.row(i).cwiseAbs().maxCoeff() < 5e-5) continue;
      fmt::print("  {:<10}", names[static_cast<std::size_t>(i)]);
      for (Eigen::Index c = 0; c < B.cols(); ++c) fmt::print(" {:>9}", fmt_num(B(i, c)));
      fmt::print("\n");
    }
    fmt::print("  (states not listed: 0 in every mode)\n");
  }
  fmt::print("unobservable states ({}, |N^T e_i| > {:g}): {}\n", unobservable.size(), r.state_tolerance,
             unobservable.empty() ? "none" : fmt::format("{}", fmt::join(unobservable, " ")));
  fmt::print("observable states: {} of {}\n", r.dim - static_cast<int>(unobservable.size()), r.dim);
  return 0;
}

}  // namespace

Subcommand add_observability(CLI::App& parent) {
  auto o = std::make_shared<ObsOptions>();
  auto* cmd = parent.add_subcommand(
      "observability",
      "Observability analysis (paper section 4): rank, unobservable modes and null space of the "
      "Lie-derivative observability matrix for a sensor set");
  cmd->add_option("--config", o->config, "Table 1 preset 1, 2 or 3 (uav1 sees the lead and carries altimeter and range)");
  cmd->add_option("--sees-lead", o->sees_lead, "UAVs that project the lead, e.g. uav1,uav2 (or none)");
  cmd->add_option("--altimeter", o->altimeter, "UAVs with an altimeter, e.g. uav1 (or none)");
  cmd->add_option("--range", o->range, "UAVs with a range sensor to the lead, e.g. uav1 (or none)");
  o->gps_opt = cmd->add_flag("--gps,!--no-gps", o->gps, "Whether the lead's GPS is fed (overrides the preset)");
  cmd->add_option("--uavs", o->uavs, "Number of UAVs (default 2)");
  cmd->add_option("--landmarks", o->landmarks, "Number of landmarks (default 6)");
  cmd->add_option("--visibility", o->visibility,
                  "Landmarks each UAV sees, e.g. uav1:0-3,uav2:2-5 (default: all, shared; unlisted UAVs see none)");
  cmd->add_option("--order", o->order, "Highest Lie-derivative order (default 1)");
  cmd->add_option("--seed", o->seed, "Seed of the generic state (default 1)");
  cmd->add_option("--tol", o->tol, "Relative singular-value tolerance of the rank (default 1e-8)");
  cmd->add_option("--state-tol", o->state_tol,
                  "A state is observable when its unit vector's projection on the null space is below this (default 1e-6)");
  cmd->add_option("--scenario", o->scenario, "Evaluate at the true state of this scenario's trajectory")
      ->check(CLI::ExistingFile);
  add_variant_option(cmd, o->variants, "Scenario variant (default: the first)");
  o->at_opt = cmd->add_option("--at", o->at, "Time on the scenario's trajectory, s (default 0)");
  cmd->add_flag("--json", o->json, "Print JSON (dim, rank, unobservable_modes, null_space, observable, ...)");
  return {cmd, [o] {
            return for_each_variant(o->variants, [&](const std::string& v) { return observability_command(*o, v); });
          }};
}

}  // namespace wingman::app
