#include "eval/metrics/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace wingman::eval {
namespace {

// Running sums for one agent's position error over a set of steps.
struct ErrorAccumulator {
  Eigen::Vector3d sq_sum = Eigen::Vector3d::Zero();
  double norm_sq_sum = 0;
  double max_norm = 0;
  int n = 0;

  void add(const Eigen::Vector3d& e) {
    sq_sum += e.cwiseAbs2();
    norm_sq_sum += e.squaredNorm();
    max_norm = std::max(max_norm, e.norm());
    ++n;
  }
  AgentError result() const {
    AgentError r;
    r.steps = n;
    if (n == 0) return r;
    r.mse = sq_sum / n;
    r.rms_error = std::sqrt(norm_sq_sum / n);
    r.max_error = max_norm;
    return r;
  }
};

struct MeanAccumulator {
  double sum = 0;
  int n = 0;
  void add(double v) {
    if (std::isfinite(v)) {
      sum += v;
      ++n;
    }
  }
  double result() const { return n > 0 ? sum / n : kNaN; }
};

LandmarkMse landmark_mse(const std::vector<const LandmarkRecord*>& set, bool use_phase_end) {
  LandmarkMse r;
  r.count = static_cast<int>(set.size());
  if (set.empty()) return r;
  Eigen::Vector3d fin = Eigen::Vector3d::Zero(), init = Eigen::Vector3d::Zero();
  for (const LandmarkRecord* l : set) {
    const Eigen::Vector3d& est = use_phase_end ? l->est_phase_end : l->est_final;
    fin += (est - l->truth).cwiseAbs2();
    init += (l->est_init - l->truth).cwiseAbs2();
  }
  r.final_mse = fin / r.count;
  r.init_mse = init / r.count;
  return r;
}

// Linear interpolation between order statistics of sorted values at quantile q.
double quantile_sorted(const std::vector<double>& v, double q) {
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace

Stats summarise(std::vector<double> values) {
  std::erase_if(values, [](double v) { return !std::isfinite(v); });
  Stats s;
  s.count = static_cast<int>(values.size());
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  double sum = 0;
  for (double v : values) sum += v;
  s.mean = sum / static_cast<double>(values.size());
  s.median = quantile_sorted(values, 0.5);
  s.p95 = quantile_sorted(values, 0.95);
  s.max = values.back();
  return s;
}

Metrics compute_metrics(const RunRecord& run) {
  const std::size_t n_agents = run.agent_names.size();
  const std::size_t n_phases = run.phases.size();

  std::vector<std::vector<ErrorAccumulator>> phase_err(
      n_phases, std::vector<ErrorAccumulator>(n_agents));
  std::vector<ErrorAccumulator> total_err(n_agents);
  std::vector<MeanAccumulator> phase_nees(n_phases);
  std::vector<std::vector<MeanAccumulator>> phase_nees_p(n_agents, std::vector<MeanAccumulator>(n_phases)),
      phase_nees_v = phase_nees_p;
  MeanAccumulator run_nees;
  ByStage<std::vector<double>> t_stage;
  std::vector<double> t_total;

  Metrics m;
  m.nees.per_step.reserve(run.steps.size());
  m.landmarks.count_per_step.reserve(run.steps.size());

  for (const StepRecord& s : run.steps) {
    if (s.agents.size() != n_agents) {
      throw std::invalid_argument("run record step k=" + std::to_string(s.k) + " has " +
                                  std::to_string(s.agents.size()) + " agents, expected " +
                                  std::to_string(n_agents));
    }
    if (s.phase >= static_cast<int>(n_phases)) {
      throw std::invalid_argument("run record step k=" + std::to_string(s.k) + " is in phase " +
                                  std::to_string(s.phase) + " but the run has " +
                                  std::to_string(n_phases) + " phases");
    }
    m.nees.per_step.push_back(s.nees);
    m.landmarks.count_per_step.push_back(s.landmarks);
    m.landmarks.max_in_state = std::max(m.landmarks.max_in_state, s.landmarks);
    if (m.nees.dof == 0 && s.nees_dof > 0) m.nees.dof = s.nees_dof;

    if (s.k == 0) continue;  // the known initial state says nothing about the filter

    run_nees.add(s.nees);
    s.t_ms.zip(t_stage, [](const char*, double ms, std::vector<double>& all, bool) { all.push_back(ms); });
    t_total.push_back(s.t_ms.total());

    if (s.phase < 0) continue;
    phase_nees[s.phase].add(s.nees);
    for (std::size_t a = 0; a < n_agents; ++a) {
      const Eigen::Vector3d e = s.agents[a].p_true - s.agents[a].p_est;
      phase_err[s.phase][a].add(e);
      total_err[a].add(e);
      phase_nees_p[a][s.phase].add(s.agents[a].nees_p);
      phase_nees_v[a][s.phase].add(s.agents[a].nees_v);
    }
  }

  for (std::size_t p = 0; p < n_phases; ++p) {
    Table4Phase row;
    row.phase = static_cast<int>(p);
    for (const ErrorAccumulator& acc : phase_err[p]) row.agents.push_back(acc.result());
    m.table4.phases.push_back(std::move(row));
    m.nees.per_phase_mean.push_back(phase_nees[p].result());
  }
  for (const ErrorAccumulator& acc : total_err) m.table4.total.push_back(acc.result());
  m.nees.mean = run_nees.result();
  for (std::size_t a = 0; a < n_agents; ++a) {
    auto& pos = m.nees.position_per_phase.emplace_back();
    auto& vel = m.nees.velocity_per_phase.emplace_back();
    for (std::size_t p = 0; p < n_phases; ++p) {
      pos.push_back(phase_nees_p[a][p].result());
      vel.push_back(phase_nees_v[a][p].result());
    }
  }

  std::vector<std::vector<const LandmarkRecord*>> by_phase(n_phases);
  std::vector<const LandmarkRecord*> all;
  for (const LandmarkRecord& l : run.landmarks) {
    all.push_back(&l);
    if (l.init_phase >= 0 && l.init_phase < static_cast<int>(n_phases)) {
      by_phase[l.init_phase].push_back(&l);
    }
  }
  for (const auto& set : by_phase) m.table5.phases.push_back(landmark_mse(set, true));
  m.table5.total = landmark_mse(all, false);

  for (const OutlierCounts& c : run.outliers) {
    OutlierRow row{c, kNaN};
    if (c.accepted > 0) {
      row.accepted_outlier_fraction =
          static_cast<double>(c.outliers_accepted) / static_cast<double>(c.accepted);
    }
    m.table3.push_back(row);
  }

  t_stage.zip(m.timings_ms, [](const char*, const std::vector<double>& all, Stats& st, bool) { st = summarise(all); });
  m.timings_ms.total = summarise(std::move(t_total));
  if (run.frontend.enabled) {
    const FrontendRecord& f = run.frontend;
    m.frontend.present = true;
    m.frontend.frames = f.frames;
    m.frontend.lead_in_view = f.lead_in_view;
    m.frontend.lead_detected = f.lead_detected;
    m.frontend.lead_false = f.lead_false;
    if (f.lead_in_view > 0)
      m.frontend.lead_detection_rate = static_cast<double>(f.lead_detected) / f.lead_in_view;
    m.frontend.lead_error_px = summarise(f.lead_error_px);
    m.frontend.accepted_error_px = summarise(f.accepted_error_px);
    m.frontend.accepted_error_histogram.assign(std::size(FrontendMetrics::kErrorBins) + 1, 0);
    for (double e : f.accepted_error_px) {
      if (!std::isfinite(e)) continue;
      const auto* bin = std::upper_bound(std::begin(FrontendMetrics::kErrorBins),
                                         std::end(FrontendMetrics::kErrorBins), e);
      ++m.frontend.accepted_error_histogram[bin - std::begin(FrontendMetrics::kErrorBins)];
    }
    if (f.frames > 0) m.frontend.searched_fraction = f.searched_fraction_sum / static_cast<double>(f.frames);
    if (run.steps.size() > 1)
      m.frontend.detect_busy_ms_per_step = f.detect_busy_ms / static_cast<double>(run.steps.size() - 1);
  }
  m.landmarks.initialised = static_cast<long>(run.landmarks.size());
  m.formation = compute_formation_metrics(run);
  m.consistency = diagnose_consistency(run, m);
  return m;
}

}  // namespace wingman::eval
