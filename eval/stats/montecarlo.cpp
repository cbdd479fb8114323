#include "eval/stats/montecarlo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "io/atomic_file.hpp"
#include "eval/output/json_file.hpp"
#include "eval/metrics/nees_null.hpp"
#include "geometry/chi2.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The 't' column of steps.csv.
std::vector<double> read_times(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open", path.string()));
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(fmt::format("{}: empty", path.string()));
  int col = -1, i = 0;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ','); ++i)
    if (name == "t") col = i;
  if (col < 0) throw std::runtime_error(fmt::format("{}: no 't' column", path.string()));
  std::vector<double> t;
  for (int row = 2; std::getline(in, line); ++row) {
    std::stringstream ss(line);
    std::string cell;
    for (int c = 0; c <= col; ++c) std::getline(ss, cell, ',');
    try {
      t.push_back(std::stod(cell));
    } catch (const std::exception&) {
      throw std::runtime_error(fmt::format("{}:{}: 't' is not a number", path.string(), row));
    }
  }
  return t;
}

void check_batch_size(const std::string& label, std::size_t runs, std::size_t batch_size) {
  if (batch_size < 2 || runs < batch_size)
    throw std::invalid_argument(fmt::format("{}: batches of {} runs need at least {} runs and 2 per "
                                            "batch; {} finished", label, batch_size,
                                            std::max<std::size_t>(batch_size, 2), runs));
}

double number_or_nan(const json& j) { return j.is_number() ? j.get<double>() : kNaN; }

// What an exactly consistent filter would show (eval/metrics/nees_null.hpp), from the runs' NEES
// autocorrelation over the steps where every run has one. Lags up to 60 s (a third of the run at
// most) feed the AR model; 2000 simulated batches with a fixed seed, so the figures repeat.
void consistent_filter_inside(MonteCarloSummary& m, const std::vector<std::vector<double>>& per_run,
                              std::vector<MonteCarloPhase>& phases,
                              const std::vector<std::vector<std::size_t>>& phase_steps) {
  const std::size_t steps = m.t.size();
  std::size_t first = steps, last = 0;
  for (std::size_t k = 0; k < steps; ++k)
    if (std::isfinite(m.average_nees[k])) first = std::min(first, k), last = k + 1;
  if (per_run.size() < 2 || last < first + 10) return;
  for (std::size_t k = first; k < last; ++k)
    if (!std::isfinite(m.average_nees[k])) return;  // a gap: the series is not one process
  const double dt = (m.t[last - 1] - m.t[first]) / static_cast<double>(last - 1 - first);
  const std::size_t max_lag =
      std::min<std::size_t>((last - first) / 3, dt > 0 ? static_cast<std::size_t>(std::lround(60.0 / dt)) : 0);
  const std::vector<double> acf = nees_autocorrelation(per_run, first, last, max_lag);
  m.nees_correlation_time = integrated_correlation_steps(acf) * dt;
  std::vector<std::vector<std::size_t>> ranges;
  for (const auto& idx : phase_steps) {
    ranges.emplace_back();
    for (std::size_t k : idx) ranges.back().push_back(k - first);
  }
  // "Every phase" leaves out the last range, "total".
  const auto sim = simulate_consistent_inside(fit_autoregression(acf), last - first, ranges,
                                              ranges.size() - 1, kInsideTarget, 2000, 1);
  for (std::size_t i = 0; i < phases.size(); ++i) {
    phases[i].consistent_median_inside = sim.median[i];
    phases[i].consistent_p_below_target = sim.p_below[i];
  }
  m.consistent_p_all_phases_at_target = sim.p_all_at_target;
}

}  // namespace

Spread spread_of(const std::vector<double>& values) {
  Spread s;
  double sum = 0, sum2 = 0;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    sum += v;
    sum2 += v * v;
    s.min = s.n == 0 ? v : std::min(s.min, v);
    s.max = s.n == 0 ? v : std::max(s.max, v);
    ++s.n;
  }
  if (s.n == 0) return s;
  s.mean = sum / s.n;
  s.std = s.n > 1 ? std::sqrt(std::max(0.0, (sum2 - s.n * s.mean * s.mean) / (s.n - 1))) : 0.0;
  return s;
}

double mean_nees_halfwidth95(const Spread& run_means) {
  if (run_means.n < 2) return kNaN;
  return kZ975 * run_means.std / std::sqrt(static_cast<double>(run_means.n));
}

MonteCarloSummary aggregate_runs(const std::string& label, const std::vector<fs::path>& run_dirs) {
  return aggregate_runs(label, RunSet(run_dirs));
}

MonteCarloSummary aggregate_runs(const std::string& label, const RunSet& runs) {
  if (runs.empty()) throw std::runtime_error(fmt::format("{}: no finished runs", label));
  const std::vector<fs::path>& run_dirs = runs.dirs();
  MonteCarloSummary m;
  m.label = label;
  m.runs = static_cast<int>(run_dirs.size());
  std::vector<std::reference_wrapper<const json>> metrics;
  for (std::size_t r = 0; r < runs.size(); ++r) metrics.emplace_back(run_metrics(runs, r));
  m.t = read_times(run_dirs.front() / "steps.csv");
  const std::size_t steps = m.t.size();

  // Average NEES per step over the runs that have it (none at k = 0, before any update).
  std::vector<double> sum(steps, 0.0);
  std::vector<int> count(steps, 0);
  std::vector<std::vector<double>> per_run(metrics.size(), std::vector<double>(steps, kNaN));
  for (std::size_t r = 0; r < metrics.size(); ++r) {
    const json& nees = metrics[r].get().at("nees");
    const auto& per_step = nees.at("per_step");
    if (per_step.size() != steps)
      throw std::runtime_error(fmt::format("{}: {} NEES steps, the first run has {}",
                                           (run_dirs[r] / "metrics.json").string(), per_step.size(),
                                           steps));
    const int dof = nees.at("dof").get<int>();
    if (r == 0) m.dof = dof;
    if (dof != m.dof)
      throw std::runtime_error(fmt::format("{}: NEES over {} dof, the first run has {}",
                                           (run_dirs[r] / "metrics.json").string(), dof, m.dof));
    for (std::size_t k = 0; k < steps; ++k)
      if (const double v = number_or_nan(per_step[k]); std::isfinite(v))
        sum[k] += v, ++count[k], per_run[r][k] = v;
  }
  m.average_nees.assign(steps, kNaN);
  for (std::size_t k = 0; k < steps; ++k)
    if (count[k] == m.runs) m.average_nees[k] = sum[k] / m.runs;
  if (m.dof > 0) {
    const double dn = static_cast<double>(m.dof) * m.runs;
    m.lower = geometry::chi2_quantile(0.025, dn) / m.runs;
    m.upper = geometry::chi2_quantile(0.975, dn) / m.runs;
  }

  // Per phase (from the first run; every run of a variant shares them) and the whole run.
  std::vector<MonteCarloPhase> phases;
  for (const auto& p : metrics.front().get().at("phases")) {
    MonteCarloPhase ph;
    ph.name = p.at("name").get<std::string>();
    ph.t_start = p.at("t_start").get<double>();
    ph.t_end = p.at("t_end").get<double>();
    phases.push_back(ph);
  }
  MonteCarloPhase total;
  total.name = "total";
  total.t_start = m.t.empty() ? 0 : m.t.front();
  total.t_end = m.t.empty() ? 0 : m.t.back();
  // Step indices of each phase with an average NEES, for the consistent-filter simulation.
  std::vector<std::vector<std::size_t>> phase_steps;
  auto bounds_count = [&](MonteCarloPhase& ph, bool whole) {
    double nees_sum = 0;
    std::vector<std::size_t> indices;
    std::vector<double> run_sum(per_run.size(), 0.0);
    for (std::size_t k = 0; k < steps; ++k) {
      const double v = m.average_nees[k];
      if (!std::isfinite(v)) continue;
      const bool in_phase = whole || (m.t[k] >= ph.t_start && (m.t[k] < ph.t_end ||
                                                                (&ph == &phases.back() && m.t[k] <= ph.t_end)));
      if (!in_phase) continue;
      ++ph.steps;
      nees_sum += v;
      if (v >= m.lower && v <= m.upper) ++ph.inside;
      indices.push_back(k);
      for (std::size_t r = 0; r < per_run.size(); ++r) run_sum[r] += per_run[r][k];
    }
    if (ph.steps > 0) {
      ph.fraction_inside = static_cast<double>(ph.inside) / ph.steps;
      ph.mean_nees = nees_sum / ph.steps;
      for (double& x : run_sum) x /= ph.steps;
      ph.run_mean_nees = spread_of(run_sum);
    }
    phase_steps.push_back(std::move(indices));
  };
  // Table 4 spreads; `pick` finds the agents' object: table4.phases[i].agents or table4.total.
  auto table4_spread = [&](MonteCarloPhase& ph, const json* (*pick)(const json&, std::size_t),
                           std::size_t index) {
    const json* first = pick(metrics.front().get(), index);
    if (!first) return;
    for (auto it = first->begin(); it != first->end(); ++it) {
      AgentSpread a;
      a.agent = it.key();
      for (int axis = 0; axis < 3; ++axis) {
        std::vector<double> v;
        for (const json& mj : metrics)
          if (const json* p = pick(mj, index); p && p->contains(a.agent))
            v.push_back(number_or_nan(p->at(a.agent).at("mse").at(axis)));
        a.mse[axis] = spread_of(v);
      }
      ph.agents.push_back(a);
    }
  };
  // Block NEES of phase `index`, from each run's nees.per_agent (absent in older metrics.json).
  auto block_nees = [&](MonteCarloPhase& ph, std::size_t index) {
    const json& first = metrics.front().get().at("nees");
    if (!first.contains("per_agent")) return;
    for (auto it = first.at("per_agent").begin(); it != first.at("per_agent").end(); ++it) {
      BlockNees b;
      b.agent = it.key();
      std::vector<double> pos, vel;
      for (const json& mj : metrics) {
        const json& n = mj.at("nees");
        if (!n.contains("per_agent") || !n.at("per_agent").contains(b.agent)) continue;
        const json& a = n.at("per_agent").at(b.agent);
        const json& p = a.at("position_per_phase_mean");
        const json& v = a.at("velocity_per_phase_mean");
        if (index < p.size()) pos.push_back(number_or_nan(p[index]));
        if (index < v.size()) vel.push_back(number_or_nan(v[index]));
      }
      b.position = spread_of(pos);
      b.velocity = spread_of(vel);
      ph.blocks.push_back(b);
    }
  };
  for (std::size_t i = 0; i < phases.size(); ++i) {
    bounds_count(phases[i], false);
    block_nees(phases[i], i);
    table4_spread(phases[i], [](const json& mj, std::size_t idx) -> const json* {
      const auto& ps = mj.at("table4").at("phases");
      return idx < ps.size() ? &ps[idx].at("agents") : nullptr;
    }, i);
  }
  bounds_count(total, true);
  table4_spread(total, [](const json& mj, std::size_t) -> const json* {
    return &mj.at("table4").at("total");
  }, 0);
  phases.push_back(total);
  consistent_filter_inside(m, per_run, phases, phase_steps);
  m.phases = std::move(phases);
  return m;
}

double poisson_binomial_cdf(const std::vector<double>& p, int k) {
  if (k < 0) return 0.0;
  // dist[j]: probability of j successes among the trials so far.
  std::vector<double> dist = {1.0};
  for (double q : p) {
    dist.push_back(0.0);
    for (std::size_t j = dist.size() - 1; j > 0; --j) dist[j] = dist[j] * (1 - q) + dist[j - 1] * q;
    dist[0] *= 1 - q;
  }
  double sum = 0;
  for (std::size_t j = 0; j < dist.size() && static_cast<int>(j) <= k; ++j) sum += dist[j];
  return std::min(1.0, sum);
}

BatchTest test_batches(const std::string& label, const std::vector<fs::path>& run_dirs,
                       std::size_t batch_size) {
  check_batch_size(label, run_dirs.size(), batch_size);  // before reading any file
  return test_batches(label, RunSet(run_dirs), batch_size);
}

BatchTest test_batches(const std::string& label, const RunSet& runs, std::size_t batch_size) {
  const std::vector<fs::path>& run_dirs = runs.dirs();
  check_batch_size(label, run_dirs.size(), batch_size);
  BatchTest bt;
  bt.batch_size = batch_size;
  std::vector<double> p_pass;
  for (std::size_t first = 0; first + batch_size <= run_dirs.size(); first += batch_size) {
    const MonteCarloSummary m = aggregate_runs(label, runs.slice(first, batch_size));
    Batch b;
    b.first = first;
    b.size = batch_size;
    b.label = fmt::format("runs {}-{}", first + 1, first + batch_size);
    b.passed = true;
    for (std::size_t i = 0; i + 1 < m.phases.size(); ++i) {  // the last is "total"
      b.fraction_inside.push_back(m.phases[i].fraction_inside);
      b.passed = b.passed && m.phases[i].fraction_inside >= kInsideTarget;
    }
    b.consistent_p_pass = m.consistent_p_all_phases_at_target;
    bt.passed += b.passed;
    p_pass.push_back(b.consistent_p_pass);
    bt.batches.push_back(std::move(b));
  }
  if (std::all_of(p_pass.begin(), p_pass.end(), [](double q) { return std::isfinite(q); })) {
    bt.consistent_expected_passes = 0;
    for (double q : p_pass) bt.consistent_expected_passes += q;
    bt.consistent_p_at_most_passed = poisson_binomial_cdf(p_pass, bt.passed);
  }
  return bt;
}

std::string recorded_numerical_failure(const fs::path& run_dir) {
  const json j = read_json_file(run_dir / "metrics.json");
  const auto it = j.find("numerical_failure");
  if (it == j.end() || it->is_null()) return "";
  return it->value("message", std::string("numerical failure"));
}

void write_monte_carlo(const std::vector<MonteCarloSummary>& summaries, const fs::path& dir,
                       const MonteCarloProvenance& prov) {
  json out = json::array();
  for (const auto& m : summaries) {
    json j;
    j["label"] = m.label;
    j["runs"] = m.runs;
    j["nees_dof"] = m.dof;
    j["nees_bounds"] = {m.lower, m.upper};
    j["nees_correlation_time_s"] = m.nees_correlation_time;
    j["consistent_filter_p_all_phases_inside_target"] = m.consistent_p_all_phases_at_target;
    j["inside_target"] = kInsideTarget;
    auto spread = [](const Spread& s) {
      return json{{"mean", s.mean}, {"std", s.std}, {"min", s.min}, {"max", s.max}, {"n", s.n}};
    };
    for (const auto& p : m.phases) {
      json jp{{"name", p.name},         {"t_start", p.t_start},
              {"t_end", p.t_end},       {"nees_steps", p.steps},
              {"nees_inside", p.inside}, {"nees_fraction_inside", p.fraction_inside},
              {"nees_mean", p.mean_nees}};
      const double hw = mean_nees_halfwidth95(p.run_mean_nees);
      jp["nees_run_means"] = spread(p.run_mean_nees);
      jp["nees_mean_ci95"] = {p.run_mean_nees.mean - hw, p.run_mean_nees.mean + hw};
      jp["consistent_filter"] = {{"median_fraction_inside", p.consistent_median_inside},
                                 {"p_fraction_below_target", p.consistent_p_below_target}};
      for (const auto& a : p.agents)
        jp["mse"][a.agent] = {spread(a.mse[0]), spread(a.mse[1]), spread(a.mse[2])};
      for (const auto& b : p.blocks)
        jp["nees_blocks"][b.agent] = {{"position", spread(b.position)}, {"velocity", spread(b.velocity)}};
      j["phases"].push_back(jp);
    }
    if (m.batches) {
      const BatchTest& bt = *m.batches;
      json jb{{"batch_size", bt.batch_size},
              {"passed", bt.passed},
              {"consistent_filter_expected_passes", bt.consistent_expected_passes},
              {"consistent_filter_p_at_most_passed", bt.consistent_p_at_most_passed},
              {"batches", json::array()}};
      for (const auto& b : bt.batches)
        jb["batches"].push_back({{"label", b.label},
                                 {"first_run", b.first},
                                 {"runs", b.size},
                                 {"fraction_inside", b.fraction_inside},
                                 {"passed", b.passed},
                                 {"consistent_filter_p_pass", b.consistent_p_pass}});
      j["batch_test"] = jb;
    }
    out.push_back(j);
  }
  json failed = json::array();
  for (const auto& [seed, why] : prov.failed) failed.push_back({{"seed", seed}, {"reason", why}});
  const json doc{{"scenario", prov.scenario},
                 {"scenario_fnv1a64", prov.scenario_hash},
                 {"seeds", prov.seeds},
                 {"failed_seeds", failed},
                 {"variants", out}};
  io::write_file_atomic(dir / "montecarlo.json", doc.dump(2, ' ', false, json::error_handler_t::replace) + "\n");

  std::string csv = "t";
  for (const auto& m : summaries) csv += fmt::format(",{0}_nees,{0}_lower,{0}_upper", m.label);
  csv += "\n";
  const std::size_t steps = summaries.empty() ? 0 : summaries.front().t.size();
  for (std::size_t k = 0; k < steps; ++k) {
    csv += fmt::format("{:.6f}", summaries.front().t[k]);
    for (const auto& m : summaries) {
      const double v = k < m.average_nees.size() ? m.average_nees[k] : kNaN;
      csv += fmt::format(",{},{:.6g},{:.6g}", std::isfinite(v) ? fmt::format("{:.6g}", v) : std::string(),
                         m.lower, m.upper);
    }
    csv += "\n";
  }
  io::write_file_atomic(dir / "nees.csv", csv);
}

namespace {

// What a phase with few steps inside its bounds says about the filter: too little NEES is a filter
// that assumes more noise than the runs realise, too much one that trusts its estimate too far.
std::string why_outside(const MonteCarloSummary& m) {
  std::string s;
  for (const auto& p : m.phases) {
    if (!(p.fraction_inside < kInsideTarget) || !std::isfinite(p.mean_nees)) continue;
    if (p.mean_nees < m.lower)
      s += fmt::format("{}: mean NEES {:.2f} lies below the bounds: the filter assumes more noise than the "
                       "runs realise (a truth that never draws the process noise, as the paper's "
                       "deterministic eq. 66, does this; docs/studies/nees-consistency.md)\n",
                       p.name, p.mean_nees);
    else if (p.mean_nees > m.upper)
      s += fmt::format("{}: mean NEES {:.2f} lies above the bounds: the filter's covariance is smaller than "
                       "its errors (overconfident)\n",
                       p.name, p.mean_nees);
  }
  return s;
}

}  // namespace

std::string format_monte_carlo(const std::vector<MonteCarloSummary>& summaries) {
  std::string s;
  for (const auto& m : summaries) {
    s += fmt::format("\n{}: {} runs, average NEES over {} dof, 95% bounds [{:.2f}, {:.2f}]\n", m.label,
                     m.runs, m.dof, m.lower, m.upper);
    s += fmt::format("{:<10} {:>8} {:>9}", "phase", "mean NEES", "inside");
    const auto& agents = m.phases.front().agents;
    for (const auto& a : agents)
      for (const char* ax : {"X", "Y", "Z"}) s += fmt::format(" {:>15}", a.agent + " " + ax);
    s += "\n";
    for (const auto& p : m.phases) {
      s += fmt::format("{:<10} {:>8.2f} {:>8.1f}%", p.name, p.mean_nees, 100 * p.fraction_inside);
      for (const auto& a : p.agents)
        for (const auto& sp : a.mse) s += fmt::format(" {:>7.4f}±{:<7.4f}", sp.mean, sp.std);
      s += "\n";
    }
    s += why_outside(m);
    s += fmt::format("consistency (a consistent filter averages {}; its NEES decorrelates over {:.1f} s):\n",
                     m.dof, m.nees_correlation_time);
    s += fmt::format("{:<10} {:>8} {:>24} {:>29} {:>16}\n", "phase", "inside", "mean NEES [95% CI]",
                     "consistent filter: inside", fmt::format("P(< {:.0f}%)", 100 * kInsideTarget));
    for (const auto& p : m.phases) {
      const double hw = mean_nees_halfwidth95(p.run_mean_nees);
      s += fmt::format("{:<10} {:>7.1f}% {:>8.2f} [{:>6.2f}, {:>6.2f}] {:>28.1f}% {:>15.1f}%\n", p.name,
                       100 * p.fraction_inside, p.run_mean_nees.mean, p.run_mean_nees.mean - hw,
                       p.run_mean_nees.mean + hw, 100 * p.consistent_median_inside,
                       100 * p.consistent_p_below_target);
    }
    s += fmt::format("a consistent filter puts every phase at >= {:.0f}% inside with probability {:.0f}%\n",
                     100 * kInsideTarget, 100 * m.consistent_p_all_phases_at_target);
    if (m.batches) {
      const BatchTest& bt = *m.batches;
      s += fmt::format("batches of {} runs, each against its own bounds:\n{:<12}", bt.batch_size, "batch");
      for (std::size_t i = 0; i + 1 < m.phases.size(); ++i) s += fmt::format(" {:>9}", m.phases[i].name);
      s += fmt::format(" {:>6} {:>26}\n", "pass", "consistent filter passes");
      for (const auto& b : bt.batches) {
        s += fmt::format("{:<12}", b.label);
        for (double f : b.fraction_inside) s += fmt::format(" {:>8.1f}%", 100 * f);
        s += fmt::format(" {:>6} {:>25.0f}%\n", b.passed ? "yes" : "no", 100 * b.consistent_p_pass);
      }
      s += fmt::format("{} of {} batches pass; a consistent filter passes {:.1f} on average, and {} or "
                       "fewer with probability {:.0f}%\n", bt.passed, bt.batches.size(),
                       bt.consistent_expected_passes, bt.passed, 100 * bt.consistent_p_at_most_passed);
    }
    if (m.phases.front().blocks.empty()) continue;
    s += fmt::format("{:<10}", "NEES/block");
    for (const auto& b : m.phases.front().blocks)
      for (const char* q : {"pos", "vel"}) s += fmt::format(" {:>11}", b.agent + " " + q);
    s += "\n";
    for (const auto& p : m.phases) {
      if (p.blocks.empty()) continue;
      s += fmt::format("{:<10}", p.name);
      for (const auto& b : p.blocks)
        for (const Spread* q : {&b.position, &b.velocity})
          s += fmt::format(" {:>11}", fmt::format("{:.2f}±{:.2f}", q->mean, mean_nees_halfwidth95(*q)));
      s += "\n";
    }
  }
  s += "(MSE in m^2: mean ± std over the runs; NEES/block: 3 dof each, 3 when consistent, ± the 95% "
       "half-width over the runs)\n";
  return s;
}

}  // namespace wingman::eval
