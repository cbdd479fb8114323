#include "eval/metrics/formation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace wingman::eval {
namespace {

struct Acc {
  Eigen::Vector4d sq = Eigen::Vector4d::Zero(), mx = Eigen::Vector4d::Zero();
  int n = 0;
  void add(const Eigen::Vector4d& e) {
    sq += e.cwiseAbs2();
    mx = mx.cwiseMax(e.cwiseAbs());
    ++n;
  }
  FormationError result() const {
    FormationError r;
    r.steps = n;
    if (n > 0) {
      r.rms = (sq / n).cwiseSqrt();
      r.max_abs = mx;
    }
    return r;
  }
};

double min_distance(const StepRecord& s) {
  double d = kNaN;
  for (std::size_t a = 0; a < s.formation.size(); ++a)
    for (std::size_t b = a + 1; b < s.formation.size(); ++b) {
      const double x = (s.formation[a].position_true - s.formation[b].position_true).norm();
      d = std::isnan(d) ? x : std::min(d, x);
    }
  return d;
}

double fmin_nan(double a, double b) { return std::isnan(a) ? b : (std::isnan(b) ? a : std::min(a, b)); }

}  // namespace

FormationMetrics compute_formation_metrics(const RunRecord& run) {
  FormationMetrics m;
  if (!run.closed_loop) return m;
  m.present = true;
  m.settling_time = run.settling_time;
  const std::size_t nu = run.formation_uavs.size(), np = run.phases.size();
  std::vector<std::vector<Acc>> pt(np, std::vector<Acc>(nu)), pc(np, std::vector<Acc>(nu));
  std::vector<Acc> tt(nu), tc(nu);
  std::vector<double> pmin(np, kNaN);
  long commands = 0, limited = 0;
  for (const StepRecord& s : run.steps) {
    if (s.formation.size() != nu)
      throw std::invalid_argument(fmt::format("run record step k={} has {} formation entries, "
                                              "expected {}", s.k, s.formation.size(), nu));
    const double d = min_distance(s);
    m.min_inter_uav_distance = fmin_nan(m.min_inter_uav_distance, d);
    for (const FormationStep& f : s.formation) {
      ++commands;
      if (f.limited) ++limited;
    }
    if (s.phase < 0 || s.phase >= static_cast<int>(np)) continue;
    pmin[s.phase] = fmin_nan(pmin[s.phase], d);
    if (s.t < run.phases[s.phase].t_start + run.settling_time - 1e-9) continue;
    for (std::size_t u = 0; u < nu; ++u) {
      pt[s.phase][u].add(s.formation[u].error_true());
      pc[s.phase][u].add(s.formation[u].error_est());
      tt[u].add(s.formation[u].error_true());
      tc[u].add(s.formation[u].error_est());
    }
  }
  for (std::size_t p = 0; p < np; ++p) {
    FormationPhase fp;
    fp.phase = static_cast<int>(p);
    fp.t_from = run.phases[p].t_start + run.settling_time;
    for (std::size_t u = 0; u < nu; ++u) {
      fp.truth.push_back(pt[p][u].result());
      fp.controller.push_back(pc[p][u].result());
    }
    fp.min_inter_uav_distance = pmin[p];
    m.phases.push_back(fp);
  }
  for (std::size_t u = 0; u < nu; ++u) {
    m.total_truth.push_back(tt[u].result());
    m.total_controller.push_back(tc[u].result());
  }
  m.limited_fraction = commands > 0 ? static_cast<double>(limited) / commands : kNaN;
  return m;
}

void write_formation_csv(const RunRecord& run, const std::filesystem::path& path) {
  if (!run.closed_loop) return;
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "k,t,phase");
  const char* comp[4] = {"lx", "ly", "lz", "psi"};
  for (const std::string& u : run.formation_uavs) {
    for (const char* kind : {"true", "est"})
      for (const char* what : {"", "d_", "e_"})
        for (const char* c : comp) fmt::format_to(out, ",{}_{}{}_{}", u, what, c, kind);
    for (const char* c : comp) fmt::format_to(out, ",{}_s_{}", u, c);
    for (const char* c : {"vx", "vy", "vz", "w"}) fmt::format_to(out, ",{}_cmd_{}", u, c);
    fmt::format_to(out, ",{0}_x,{0}_y,{0}_z,{0}_yaw_true,{0}_yaw_ahrs,{0}_limited", u);
  }
  fmt::format_to(out, ",min_inter_uav_distance\n");
  auto put4 = [&](const Eigen::Vector4d& v) {
    for (int i = 0; i < 4; ++i) fmt::format_to(out, ",{}", v(i));
  };
  for (const StepRecord& s : run.steps) {
    fmt::format_to(out, "{},{},{}", s.k, s.t, s.phase);
    for (const FormationStep& f : s.formation) {
      put4(f.lambda_true);
      put4(f.lambda_d_true);
      put4(f.error_true());
      put4(f.lambda_est);
      put4(f.lambda_d_est);
      put4(f.error_est());
      put4(f.surface);
      put4(f.command);
      fmt::format_to(out, ",{},{},{},{},{},{}", f.position_true.x(), f.position_true.y(),
                     f.position_true.z(), f.yaw_true, f.yaw_ahrs, f.limited ? 1 : 0);
    }
    fmt::format_to(out, ",{}\n", min_distance(s));
  }
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream o(path, std::ios::binary | std::ios::trunc);
  o.write(b.data(), static_cast<std::streamsize>(b.size()));
  o.close();
  if (!o) throw std::runtime_error("cannot write '" + path.string() + "'");
}

std::string format_formation_summary(const FormationMetrics& m, const RunRecord& run) {
  if (!m.present) return "";
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  auto cell = [](double v, int prec) {
    return std::isfinite(v) ? fmt::format("{:>7.{}f}", v, prec) : fmt::format("{:>7}", "-");
  };
  std::size_t nw = 6;
  for (const PhaseInfo& p : run.phases) nw = std::max(nw, p.name.size());
  fmt::format_to(out,
                 "\nFormation error lambda - lambda_d after {:g} s settling, true (controller's "
                 "view): RMS [m, m, m, rad]\n",
                 m.settling_time);
  fmt::format_to(out, "{:<{}} {:<6}", "phase", nw, "uav");
  for (const char* h : {"lx", "ly", "lz", "psi"}) fmt::format_to(out, " {:>15}", h);
  fmt::format_to(out, " {:>9}\n", "min dist");
  auto row = [&](const std::string& name, std::size_t u, const FormationError& t,
                 const FormationError& c, double dmin) {
    fmt::format_to(out, "{:<{}} {:<6}", name, nw, run.formation_uavs[u]);
    for (int i = 0; i < 4; ++i) fmt::format_to(out, " {} ({})", cell(t.rms(i), 3), cell(c.rms(i), 3));
    fmt::format_to(out, " {}\n", u == 0 ? cell(dmin, 2) + "  " : std::string());
  };
  for (const FormationPhase& p : m.phases)
    for (std::size_t u = 0; u < run.formation_uavs.size(); ++u)
      row(run.phases[p.phase].name, u, p.truth[u], p.controller[u], p.min_inter_uav_distance);
  for (std::size_t u = 0; u < run.formation_uavs.size(); ++u)
    row("total", u, m.total_truth[u], m.total_controller[u], m.min_inter_uav_distance);
  fmt::format_to(out, "Max |lambda - lambda_d| after settling, true:");
  for (std::size_t u = 0; u < run.formation_uavs.size(); ++u) {
    const auto& e = m.total_truth[u].max_abs;
    fmt::format_to(out, " {} [{:.2f} {:.2f} {:.2f} {:.3f}]", run.formation_uavs[u], e(0), e(1), e(2), e(3));
  }
  fmt::format_to(out, "; commands clipped by a limit: {:.1f} %\n", 100 * m.limited_fraction);
  return fmt::to_string(b);
}

}  // namespace wingman::eval
