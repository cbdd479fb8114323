#include "eval/stats/paired.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "io/atomic_file.hpp"
#include "eval/output/json_file.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

void check_same_seeds(const std::string& a, std::size_t n_a, const std::string& b, std::size_t n_b) {
  if (n_a != n_b)
    throw std::invalid_argument(fmt::format("compare_paired: {} runs of {} against {} of {}", n_a, a, n_b, b));
}

// The three numbers at j[keys...], or a runtime_error naming the file and the key.
std::vector<double> triple(const json& j, const std::vector<std::string>& keys, const fs::path& dir) {
  const json* p = &j;
  std::string where;
  for (const auto& k : keys) {
    where += (where.empty() ? "" : ".") + k;
    if (!p->is_object() || !p->contains(k))
      throw std::runtime_error(fmt::format("{}: no '{}'", (dir / "metrics.json").string(), where));
    p = &(*p)[k];
  }
  if (!p->is_array() || p->size() != 3)
    throw std::runtime_error(fmt::format("{}: '{}' is not three numbers", (dir / "metrics.json").string(), where));
  std::vector<double> v;
  for (const auto& x : *p) v.push_back(x.is_number() ? x.get<double>() : kNaN);
  return v;
}

// Student's t density with `dof` degrees of freedom.
double t_density(double t, double dof) {
  const double c = std::lgamma(0.5 * (dof + 1)) - std::lgamma(0.5 * dof) - 0.5 * std::log(dof * M_PI);
  return std::exp(c - 0.5 * (dof + 1) * std::log1p(t * t / dof));
}

// P(T <= t) for t >= 0: 1/2 plus the density integrated by Simpson's rule (smooth, unimodal).
double t_cdf_nonnegative(double t, double dof) {
  constexpr int kIntervals = 2000;  // even
  const double h = t / kIntervals;
  double sum = t_density(0, dof) + t_density(t, dof);
  for (int i = 1; i < kIntervals; ++i) sum += (i % 2 ? 4 : 2) * t_density(i * h, dof);
  return 0.5 + sum * h / 3;
}

}  // namespace

double sign_test_p(int k, int n) {
  if (n <= 0) return kNaN;
  const int m = std::min(k, n - k);
  // log C(n, i) - n log 2, summed in linear space (n is at most a few thousand seeds).
  double tail = 0;
  for (int i = 0; i <= m; ++i)
    tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) - n * std::log(2.0));
  return std::min(1.0, 2 * tail);
}

double student_t_quantile(double p, double dof) {
  if (!(p > 0 && p < 1) || !(dof >= 1))
    throw std::invalid_argument(fmt::format("student_t_quantile: p = {} must be in (0, 1) and dof = {} >= 1", p, dof));
  if (p < 0.5) return -student_t_quantile(1 - p, dof);
  double lo = 0, hi = 1;
  while (t_cdf_nonnegative(hi, dof) < p) hi *= 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (t_cdf_nonnegative(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

PairedRow compare_values(const std::vector<double>& a, const std::vector<double>& b) {
  PairedRow r;
  std::vector<double> logs;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    if (!(std::isfinite(a[i]) && std::isfinite(b[i]) && a[i] > 0 && b[i] > 0)) continue;
    ++r.seeds;
    if (b[i] > a[i]) ++r.b_worse;
    logs.push_back(std::log(b[i] / a[i]));
  }
  r.sign_p = sign_test_p(r.b_worse, r.seeds);
  if (logs.size() < 2) return r;
  const double n = static_cast<double>(logs.size());
  double mean = 0, var = 0;
  for (double x : logs) mean += x / n;
  for (double x : logs) var += (x - mean) * (x - mean) / (n - 1);
  const double hw = student_t_quantile(0.975, n - 1) * std::sqrt(var / n);
  r.ratio = std::exp(mean);
  r.ratio_lo = std::exp(mean - hw);
  r.ratio_hi = std::exp(mean + hw);
  return r;
}

PairedComparison compare_paired(const std::string& a, const std::vector<fs::path>& dirs_a,
                                const std::string& b, const std::vector<fs::path>& dirs_b) {
  check_same_seeds(a, dirs_a.size(), b, dirs_b.size());
  return compare_paired(a, RunSet(dirs_a), b, RunSet(dirs_b));  // checked before reading any file
}

PairedComparison compare_paired(const std::string& a, const RunSet& runs_a, const std::string& b,
                                const RunSet& runs_b) {
  const std::vector<fs::path>& dirs_a = runs_a.dirs();
  const std::vector<fs::path>& dirs_b = runs_b.dirs();
  check_same_seeds(a, dirs_a.size(), b, dirs_b.size());
  PairedComparison c{a, b, static_cast<int>(dirs_a.size()), {}};
  if (dirs_a.empty()) return c;
  std::vector<std::reference_wrapper<const json>> ja, jb;
  for (std::size_t i = 0; i < dirs_a.size(); ++i) {
    ja.emplace_back(run_metrics(runs_a, i));
    jb.emplace_back(run_metrics(runs_b, i));
  }
  // j[k1][k2]..., or null where a key is missing (json's const operator[] must not be given one).
  static const json kNull;
  auto at_path = [](const json& j, std::initializer_list<const char*> keys) -> const json& {
    const json* p = &j;
    for (const char* k : keys) {
      if (!p->is_object() || !p->contains(k)) return kNull;
      p = &(*p)[k];
    }
    return *p;
  };
  // Table 4's agents of A (in its order) that B has too, read from the first seed.
  std::vector<std::string> agents;
  const json& total = at_path(ja.front(), {"table4", "total"});
  if (!total.is_object())
    throw std::runtime_error(fmt::format("{}: no 'table4.total'", (dirs_a.front() / "metrics.json").string()));
  for (const auto& [agent, v] : total.items())
    if (const json& tb = at_path(jb.front(), {"table4", "total"}); tb.is_object() && tb.contains(agent))
      agents.push_back(agent);
  // nlohmann's object keys are sorted; put the lead first, as the tables do.
  std::stable_partition(agents.begin(), agents.end(), [](const std::string& s) { return s == "lead"; });

  auto add = [&](const std::string& quantity, const std::string& label, const std::vector<std::string>& keys) {
    std::vector<std::vector<double>> va, vb;
    for (std::size_t i = 0; i < ja.size(); ++i) {
      va.push_back(triple(ja[i], keys, dirs_a[i]));
      vb.push_back(triple(jb[i], keys, dirs_b[i]));
    }
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> xa, xb;
      for (std::size_t i = 0; i < va.size(); ++i) xa.push_back(va[i][axis]), xb.push_back(vb[i][axis]);
      PairedRow r = compare_values(xa, xb);
      r.quantity = quantity;
      r.agent = label;
      r.axis = axis;
      c.rows.push_back(r);
    }
  };
  for (const auto& agent : agents) add("table4", agent, {"table4", "total", agent, "mse"});
  add("table5", "landmarks", {"table5", "total", "final_mse"});

  // Per phase: the MSE triple of `agent` in the phase called `name`, or NaNs where it is missing.
  auto phase_mse = [](const json& j, const std::string& name, const std::string& agent) {
    std::vector<double> v(3, kNaN);
    if (!j.contains("table4") || !j["table4"].contains("phases") || !j["table4"]["phases"].is_array())
      return v;
    for (const auto& ph : j["table4"]["phases"]) {
      if (!ph.is_object() || !ph.contains("name") || ph["name"] != name) continue;
      if (!ph.contains("agents") || !ph["agents"].contains(agent) || !ph["agents"][agent].is_object() ||
          !ph["agents"][agent].contains("mse"))
        return v;
      const json& mse = ph["agents"][agent]["mse"];
      if (mse.is_array() && mse.size() == 3)
        for (int k = 0; k < 3; ++k) v[k] = mse[k].is_number() ? mse[k].get<double>() : kNaN;
      return v;
    }
    return v;
  };
  std::vector<std::string> phase_names;
  if (const json& t4 = at_path(ja.front(), {"table4"}); t4.is_object() && t4.contains("phases") && t4["phases"].is_array())
    for (const auto& ph : t4["phases"])
      if (ph.is_object() && ph.contains("name") && ph["name"].is_string()) phase_names.push_back(ph["name"]);
  for (const auto& name : phase_names)
    for (const auto& agent : agents)
      for (int axis = 0; axis < 3; ++axis) {
        std::vector<double> xa, xb;
        for (std::size_t i = 0; i < ja.size(); ++i) {
          xa.push_back(phase_mse(ja[i], name, agent)[axis]);
          xb.push_back(phase_mse(jb[i], name, agent)[axis]);
        }
        PairedRow r = compare_values(xa, xb);
        r.quantity = "table4";
        r.agent = agent;
        r.phase = name;
        r.axis = axis;
        c.rows.push_back(r);
      }
  return c;
}

std::string format_paired(const PairedComparison& c) {
  std::string s = fmt::format(
      "\n{} against {}, paired over {} seeds (MSE, totals then per phase; ratio: geometric mean of {} / {} "
      "with its 95% interval; p: two-sided sign test)\n",
      c.b, c.a, c.seeds, c.b, c.a);
  s += fmt::format("{:<16} {:<10} {:<4} {:>14} {:>7} {:>8} {:>18}\n", "table", "agent", "axis",
                   c.b + " worse", "p", "ratio", "95% interval");
  for (const auto& r : c.rows) {
    const std::string interval =
        std::isfinite(r.ratio_lo) ? fmt::format("[{:.2f}, {:.2f}]", r.ratio_lo, r.ratio_hi) : "-";
    const std::string table = r.quantity == "table5" ? "5 final" : r.phase.empty() ? "4" : "4 " + r.phase;
    s += fmt::format("{:<16} {:<10} {:<4} {:>14} {:>7.3f} {:>8.2f} {:>18}\n", table, r.agent,
                     std::string(1, "xyz"[r.axis]),
                     fmt::format("{} of {}", r.b_worse, r.seeds), r.sign_p, r.ratio, interval);
  }
  return s;
}

void write_paired(const std::vector<PairedComparison>& comparisons, const fs::path& path) {
  json out = json::array();
  for (const auto& c : comparisons) {
    json j{{"a", c.a}, {"b", c.b}, {"seeds", c.seeds}, {"rows", json::array()}};
    for (const auto& r : c.rows)
      j["rows"].push_back({{"quantity", r.quantity},
                           {"agent", r.agent},
                           {"phase", r.phase},
                           {"axis", std::string(1, "xyz"[r.axis])},
                           {"seeds", r.seeds},
                           {"b_worse", r.b_worse},
                           {"sign_test_p", r.sign_p},
                           {"ratio_b_over_a", r.ratio},
                           {"ratio_ci95", {r.ratio_lo, r.ratio_hi}}});
    out.push_back(j);
  }
  io::write_file_atomic(path, out.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
}

}  // namespace wingman::eval
