#include "eval/output/writers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "io/atomic_file.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

void write_file(const fs::path& path, std::string_view content) { io::write_file_atomic(path, content); }

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json vec3(const Eigen::Vector3d& v) { return json::array({num(v.x()), num(v.y()), num(v.z())}); }

json agent_error(const AgentError& e) {
  return {{"mse", vec3(e.mse)}, {"rms_error", num(e.rms_error)},
          {"max_error", num(e.max_error)}, {"steps", e.steps}};
}

json landmark_mse(const LandmarkMse& l) {
  return {{"count", l.count}, {"final_mse", vec3(l.final_mse)}, {"init_mse", vec3(l.init_mse)}};
}

json stats(const Stats& s) {
  return {{"mean", num(s.mean)}, {"median", num(s.median)}, {"p95", num(s.p95)},
          {"max", num(s.max)}, {"count", s.count}};
}

// CSV cell for a double: shortest text that reads back to the same value; an empty field where
// there is no value (the NEES at step 0, a landmark never removed), so that a "nan" or "inf" in
// a CSV is never a value wingman wrote on purpose.
void put(fmt::memory_buffer& b, double v) {
  if (std::isfinite(v)) fmt::format_to(std::back_inserter(b), ",{}", v);
  else fmt::format_to(std::back_inserter(b), ",");
}
void put3(fmt::memory_buffer& b, const Eigen::Vector3d& v) {
  put(b, v.x());
  put(b, v.y());
  put(b, v.z());
}

// Table cell: value or "-" when undefined.
std::string cell(double v, int width, int precision = 4) {
  if (!std::isfinite(v)) return fmt::format("{:>{}}", "-", width);
  return fmt::format("{:>{}.{}f}", v, width, precision);
}

std::string phase_name(const RunRecord& run, int p) {
  return p >= 0 && p < static_cast<int>(run.phases.size()) ? run.phases[p].name
                                                            : fmt::format("phase {}", p);
}

// What the numbers mean, in the file itself, so that a reader (or a baseline) never depends on a
// convention kept elsewhere.
json metrics_conventions() {
  return {
      {"axes", "every [x, y, z] is along the world frame's axes (right-handed, z up); formation "
               "components are [lambda_x, lambda_y, lambda_z, psi]"},
      {"units",
       {{"mse", "m^2"}, {"final_mse", "m^2"}, {"init_mse", "m^2"}, {"rms_error", "m"},
        {"max_error", "m"}, {"t", "s"}, {"wall_time_s", "s"}, {"timings_ms", "ms"},
        {"*_px", "px"}, {"nees", "dimensionless; a consistent filter averages dof"},
        {"formation", "m for lambda_x, lambda_y, lambda_z; rad for psi"}}},
      {"histograms", "counts has one entry more than bin_edges_px: counts[0] holds the values "
                     "below the first edge, counts[i] those in [edge[i-1], edge[i]), the last "
                     "those at or above the last edge"},
      {"missing", "null: no value (an empty set of steps, or no NEES at step 0)"}};
}

}  // namespace

void write_metrics_json(const Metrics& m, const RunRecord& run, const fs::path& path) {
  json j;
  j["schema_version"] = kMetricsSchemaVersion;
  j["conventions"] = metrics_conventions();
  j["software_version"] = run.software_version;
  j["scenario"] = {{"path", run.scenario_path},       {"name", run.scenario_name},
                   {"variant", run.variant},          {"seed", run.seed},
                   {"estimator_mode", run.estimator_mode}};
  j["agents"] = run.agent_names;
  json phases = json::array();
  for (const PhaseInfo& p : run.phases) {
    phases.push_back({{"name", p.name}, {"t_start", num(p.t_start)}, {"t_end", num(p.t_end)},
                      {"config", p.config}});
  }
  j["phases"] = phases;

  json t4_phases = json::array();
  for (const Table4Phase& row : m.table4.phases) {
    json agents = json::object();
    for (std::size_t a = 0; a < row.agents.size() && a < run.agent_names.size(); ++a) {
      agents[run.agent_names[a]] = agent_error(row.agents[a]);
    }
    t4_phases.push_back({{"phase", row.phase}, {"name", phase_name(run, row.phase)},
                         {"agents", agents}});
  }
  json t4_total = json::object();
  for (std::size_t a = 0; a < m.table4.total.size() && a < run.agent_names.size(); ++a) {
    t4_total[run.agent_names[a]] = agent_error(m.table4.total[a]);
  }
  j["table4"] = {{"phases", t4_phases}, {"total", t4_total}};

  json t5_phases = json::array();
  for (std::size_t p = 0; p < m.table5.phases.size(); ++p) {
    json row = landmark_mse(m.table5.phases[p]);
    row["phase"] = p;
    row["name"] = phase_name(run, static_cast<int>(p));
    t5_phases.push_back(row);
  }
  j["table5"] = {{"phases", t5_phases}, {"total", landmark_mse(m.table5.total)}};

  json t3 = json::array();
  for (const OutlierRow& r : m.table3) {
    t3.push_back({{"channel", r.counts.channel},
                  {"correspondences", r.counts.correspondences},
                  {"injected", r.counts.injected},
                  {"outliers", r.counts.outliers},
                  {"accepted", r.counts.accepted},
                  {"outliers_accepted", r.counts.outliers_accepted},
                  {"accepted_outlier_fraction", num(r.accepted_outlier_fraction)}});
  }
  j["table3"] = t3;

  json per_phase = json::array(), per_step = json::array();
  for (double v : m.nees.per_phase_mean) per_phase.push_back(num(v));
  for (double v : m.nees.per_step) per_step.push_back(num(v));
  json per_agent = json::object();
  for (std::size_t a = 0; a < m.nees.position_per_phase.size() && a < run.agent_names.size(); ++a) {
    json pos = json::array(), vel = json::array();
    for (double v : m.nees.position_per_phase[a]) pos.push_back(num(v));
    for (double v : m.nees.velocity_per_phase[a]) vel.push_back(num(v));
    per_agent[run.agent_names[a]] = {{"position_per_phase_mean", pos}, {"velocity_per_phase_mean", vel}};
  }
  j["nees"] = {{"dof", m.nees.dof},
               {"mean", num(m.nees.mean)},
               {"per_phase_mean", per_phase},
               {"per_agent", per_agent},
               {"per_step", per_step}};

  json findings = json::array();
  for (const ConsistencyFinding& f : m.consistency.findings) {
    json row = {{"phase", f.phase},
                {"agent", f.agent},
                {"block", f.block},
                {"nees", num(f.nees)},
                {"band", {num(f.band_lo), num(f.band_hi)}},
                {"independent_looks", num(f.independent_looks)},
                {"verdict", f.verdict}};
    // What the run did not measure (no accepted correspondence, a one-step phase) is left out.
    const std::pair<const char*, double> measured[] = {{"assumed_accel_sigma", f.assumed_accel_sigma},
                                                       {"truth_accel", f.truth_accel},
                                                       {"assumed_pixel_sigma", f.assumed_pixel_sigma},
                                                       {"pixel_error", f.pixel_error}};
    for (const auto& [key, v] : measured)
      if (std::isfinite(v)) row[key] = v;
    findings.push_back(row);
  }
  j["consistency"] = {{"blocks_checked", m.consistency.blocks_checked}, {"outside_band", findings}};

  j["timings_ms"] = {{"total", stats(m.timings_ms.total)}};
  m.timings_ms.visit([&](const char* stage, const Stats& st, bool rendered_only) {
    if (!rendered_only || m.frontend.present) j["timings_ms"][stage] = stats(st);
  });
  if (m.frontend.present) {
    const FrontendMetrics& f = m.frontend;
    j["frontend"] = {{"detector", run.frontend.detector},
                     {"renderer", run.frontend.renderer},
                     {"oracle_pixels", run.frontend.oracle_pixels},
                     {"frames", f.frames},
                     {"lead_in_view", f.lead_in_view},
                     {"lead_detected", f.lead_detected},
                     {"lead_false_detections", f.lead_false},
                     {"lead_match_px", num(run.frontend.lead_match_px)},
                     {"lead_detection_rate", num(f.lead_detection_rate)},
                     {"lead_error_px", stats(f.lead_error_px)},
                     {"detect_busy_ms_per_step", num(f.detect_busy_ms_per_step)},
                     {"searched_fraction", num(f.searched_fraction)},
                     {"accepted_error_px", stats(f.accepted_error_px)},
                     {"accepted_error_histogram",
                      {{"bin_edges_px", FrontendMetrics::kErrorBins}, {"counts", f.accepted_error_histogram}}}};
    if (const FrontendRecord& r = run.frontend; r.region_frames > 0)
      j["frame_regions"] = {{"frames", r.region_frames},
                            {"whole_frame_retries", r.whole_frame_retries},
                            {"filled_in", r.region_fills}};
    if (const FrameCacheRecord& c = run.frontend.frame_cache; c.used)
      j["frame_cache"] = {{"dir", c.dir},           {"hits", c.hits},
                          {"misses", c.misses},     {"corrupt", c.corrupt},
                          {"stores", c.stores},     {"evicted", c.evicted},
                          {"read_ms", num(c.read_ms)}, {"write_ms", num(c.write_ms)},
                          {"bytes_read", num(c.bytes_read)}, {"bytes_written", num(c.bytes_written)}};
  }
  j["landmarks"] = {{"initialised", m.landmarks.initialised},
                    {"max_in_state", m.landmarks.max_in_state},
                    {"count_per_step", m.landmarks.count_per_step}};
  if (m.formation.present) {
    const FormationMetrics& f = m.formation;
    auto v4 = [](const Eigen::Vector4d& v) {
      return json::array({num(v(0)), num(v(1)), num(v(2)), num(v(3))});
    };
    auto errs = [&](const std::vector<FormationError>& e) {
      json o = json::object();
      for (std::size_t u = 0; u < e.size() && u < run.formation_uavs.size(); ++u)
        o[run.formation_uavs[u]] = {{"rms", v4(e[u].rms)}, {"max_abs", v4(e[u].max_abs)},
                                    {"steps", e[u].steps}};
      return o;
    };
    json fp = json::array();
    for (const FormationPhase& p : f.phases)
      fp.push_back({{"phase", p.phase}, {"name", phase_name(run, p.phase)}, {"t_from", num(p.t_from)},
                    {"truth", errs(p.truth)}, {"controller", errs(p.controller)},
                    {"min_inter_uav_distance", num(p.min_inter_uav_distance)}});
    j["formation"] = {{"components", {"lambda_x", "lambda_y", "lambda_z", "psi"}},
                      {"settling_time", num(f.settling_time)},
                      {"phases", fp},
                      {"total", {{"truth", errs(f.total_truth)}, {"controller", errs(f.total_controller)}}},
                      {"min_inter_uav_distance", num(f.min_inter_uav_distance)},
                      {"limited_fraction", num(f.limited_fraction)}};
  }
  j["closed_loop"] = run.closed_loop;
  j["wall_time_s"] = num(run.wall_time_s);
  j["steps"] = run.steps.size();
  const auto& nf = run.numerical_failure;
  j["numerical_failure"] = nf.message.empty() ? json(nullptr)
                                              : json{{"step", nf.step}, {"t", nf.t}, {"message", nf.message}};
  write_file(path, j.dump(2) + "\n");
}

void write_tum_trajectories(const RunRecord& run, const fs::path& dir) {
  for (std::size_t a = 0; a < run.agent_names.size(); ++a) {
    fmt::memory_buffer est, gt;
    for (auto* b : {&est, &gt}) {
      fmt::format_to(std::back_inserter(*b), "# timestamp tx ty tz qx qy qz qw\n");
    }
    const auto line = [](fmt::memory_buffer& b, double t, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
      fmt::format_to(std::back_inserter(b), "{:.9f} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", t, p.x(),
                     p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
    };
    for (const StepRecord& s : run.steps) {
      if (a >= s.agents.size()) continue;
      line(est, s.t, s.agents[a].p_est, s.agents[a].q_est);
      line(gt, s.t, s.agents[a].p_true, s.agents[a].q_true);
    }
    write_file(dir / (run.agent_names[a] + ".est.tum"), fmt::to_string(est));
    write_file(dir / (run.agent_names[a] + ".gt.tum"), fmt::to_string(gt));
  }
}

void write_steps_csv(const RunRecord& run, const fs::path& path) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "k,t,phase");
  for (const std::string& a : run.agent_names) {
    for (const char* q : {"p", "v"}) {
      for (const char* kind : {"true", "est"}) {
        for (const char* ax : {"x", "y", "z"}) fmt::format_to(out, ",{}_{}{}_{}", a, q, ax, kind);
      }
    }
    for (const char* ax : {"x", "y", "z"}) fmt::format_to(out, ",{}_s{}", a, ax);
    fmt::format_to(out, ",{}_nees_p,{}_nees_v", a, a);
  }
  fmt::format_to(out, ",nees,landmarks");
  StepCounts{}.visit([&](const char* name, int) { fmt::format_to(out, ",{}", name); });
  StageTimings{}.visit([&](const char* stage, double, bool) { fmt::format_to(out, ",t_{}_ms", stage); });
  fmt::format_to(out, "\n");
  for (const StepRecord& s : run.steps) {
    fmt::format_to(out, "{},{},{}", s.k, s.t, s.phase);
    for (std::size_t a = 0; a < run.agent_names.size(); ++a) {
      const AgentStep as = a < s.agents.size() ? s.agents[a] : AgentStep{};
      put3(b, as.p_true);
      put3(b, as.p_est);
      put3(b, as.v_true);
      put3(b, as.v_est);
      put3(b, as.p_sigma);
      put(b, as.nees_p);
      put(b, as.nees_v);
    }
    put(b, s.nees);
    fmt::format_to(out, ",{}", s.landmarks);
    s.counts.visit([&](const char*, int n) { fmt::format_to(out, ",{}", n); });
    s.t_ms.visit([&](const char*, double ms, bool) { put(b, ms); });
    fmt::format_to(out, "\n");
  }
  write_file(path, fmt::to_string(b));
}

void write_landmarks_csv(const RunRecord& run, const fs::path& path) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out,
                 "id,truth_x,truth_y,truth_z,init_x,init_y,init_z,phase_end_x,phase_end_y,"
                 "phase_end_z,final_x,final_y,final_z,t_init,init_phase,t_removed,origin\n");
  for (const LandmarkRecord& l : run.landmarks) {
    fmt::format_to(out, "{}", l.id);
    put3(b, l.truth);
    put3(b, l.est_init);
    put3(b, l.est_phase_end);
    put3(b, l.est_final);
    put(b, l.t_init);
    fmt::format_to(out, ",{}", l.init_phase);
    put(b, l.t_removed);
    fmt::format_to(out, ",{}\n", l.origin);
  }
  write_file(path, fmt::to_string(b));
}

void write_correspondences_csv(const RunRecord& run, const fs::path& path) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "k,t,cam,landmark,u,v,true_u,true_v,outlier,accepted\n");
  for (const TrackedCorrespondence& c : run.frontend.correspondences) {
    fmt::format_to(out, "{},{:.9g},{},{},{:.6f},{:.6f},", c.k, c.t, c.cam, c.landmark, c.uv.x(),
                   c.uv.y());
    if (c.true_uv.allFinite())
      fmt::format_to(out, "{:.6f},{:.6f}", c.true_uv.x(), c.true_uv.y());
    else
      fmt::format_to(out, ",");
    fmt::format_to(out, ",{},{}\n", int(c.outlier), int(c.accepted));
  }
  write_file(path, fmt::to_string(b));
}

void write_lead_csv(const RunRecord& run, const fs::path& path) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "k,t,cam,u,v,true_u,true_v,distance,visible,box_u0,box_v0,box_u1,box_v1\n");
  auto pixel = [&](const Eigen::Vector2d& p) {
    if (p.allFinite())
      fmt::format_to(out, "{:.6f},{:.6f}", p.x(), p.y());
    else
      fmt::format_to(out, ",");
  };
  for (const LeadFrameRecord& f : run.frontend.lead_frames) {
    fmt::format_to(out, "{},{:.9g},{},", f.k, f.t, f.cam);
    pixel(f.detected);
    fmt::format_to(out, ",");
    if (!f.has_truth) {
      fmt::format_to(out, ",,,,,,,\n");
      continue;
    }
    const geometry::LeadImage& x = f.truth;
    pixel(x.uv);
    fmt::format_to(out, ",{:.6f},{:.6f},{},{},{},{}\n", x.distance, x.visible, x.box_u0, x.box_v0, x.box_u1,
                   x.box_v1);
  }
  write_file(path, fmt::to_string(b));
}

void write_map_ply(const RunRecord& run, const fs::path& path, MapPoints which) {
  std::vector<const LandmarkRecord*> kept;
  for (const LandmarkRecord& l : run.landmarks) {
    if (std::isnan(l.t_removed)) kept.push_back(&l);
  }
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out,
                 "ply\nformat ascii 1.0\ncomment wingman {} map, scenario {}\n"
                 "comment colour: blue cooperative, orange inverse_depth, grey truth\n"
                 "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                 "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
                 which == MapPoints::truth ? "truth" : "estimated", run.scenario_name,
                 kept.size());
  for (const LandmarkRecord* l : kept) {
    const Eigen::Vector3d& p = which == MapPoints::truth ? l->truth : l->est_final;
    int r = 160, g = 160, bl = 160;
    if (which == MapPoints::estimate && l->origin == "cooperative") {
      r = 31, g = 119, bl = 180;
    } else if (which == MapPoints::estimate && l->origin == "inverse_depth") {
      r = 255, g = 127, bl = 14;
    }
    fmt::format_to(out, "{:.9g} {:.9g} {:.9g} {} {} {}\n", p.x(), p.y(), p.z(), r, g, bl);
  }
  write_file(path, fmt::to_string(b));
}

void write_results(const Metrics& metrics, const RunRecord& run, const fs::path& dir) {
  fs::create_directories(dir);
  write_metrics_json(metrics, run, dir / "metrics.json");
  write_tum_trajectories(run, dir / "traj");
  write_steps_csv(run, dir / "steps.csv");
  write_landmarks_csv(run, dir / "landmarks.csv");
  write_map_ply(run, dir / "map.ply", MapPoints::estimate);
  write_map_ply(run, dir / "map_truth.ply", MapPoints::truth);
  write_formation_csv(run, dir / "formation.csv");
  if (run.frontend.record_correspondences)
    write_correspondences_csv(run, dir / "correspondences.csv");
  if (!run.frontend.lead_frames.empty()) write_lead_csv(run, dir / "lead.csv");
}

namespace {

// The blocks of the NEES outside their band, the farthest first, with what the filter assumed.
template <typename Out>
void format_consistency(Out& out, const Consistency& c) {
  if (c.findings.empty()) {
    if (c.blocks_checked > 0)
      fmt::format_to(out, "\nConsistency: every position and velocity block of the {} checked inside its band",
                     c.blocks_checked);
    return;
  }
  std::vector<const ConsistencyFinding*> f;
  for (const auto& x : c.findings) f.push_back(&x);
  auto far = [](const ConsistencyFinding* x) { return std::abs(std::log(x->nees / 3.0)); };
  std::sort(f.begin(), f.end(), [&](auto* a, auto* b) { return far(a) > far(b); });
  fmt::format_to(out, "\nConsistency: {} of {} blocks (agent x phase x position|velocity) outside their band",
                 f.size(), c.blocks_checked);
  const std::size_t shown = std::min<std::size_t>(f.size(), 6);
  for (std::size_t i = 0; i < shown; ++i) {
    const ConsistencyFinding& x = *f[i];
    fmt::format_to(out,
                   "\n  {} {} in {}: NEES {} (band {}-{} of 3, {:.0f} independent looks): {}; assumed acceleration "
                   "{} m/s^2 against the truth's {} (worst {} s RMS per axis), pixel sigma {} px against {}",
                   x.agent, x.block, x.phase, cell(x.nees, 0, 3), cell(x.band_lo, 0, 3), cell(x.band_hi, 0, 3),
                   x.independent_looks, x.verdict, cell(x.assumed_accel_sigma, 0, 3),
                   cell(x.truth_accel, 0, 3), kAccelerationWindowS, cell(x.assumed_pixel_sigma, 0, 3),
                   cell(x.pixel_error, 0, 3));
  }
  if (f.size() > shown) fmt::format_to(out, "\n  ... {} more in metrics.json (consistency)", f.size() - shown);
}

}  // namespace

std::string format_summary(const Metrics& m, const RunRecord& run) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);

  std::size_t name_w = 5;  // "total"
  for (const PhaseInfo& p : run.phases) name_w = std::max(name_w, p.name.size());
  const int nw = static_cast<int>(name_w);
  const int w = 9;

  fmt::format_to(out, "Scenario {} (variant {}, seed {}, estimator {}), {} steps, {:.1f} s wall\n",
                 run.scenario_name.empty() ? "-" : run.scenario_name,
                 run.variant.empty() ? "-" : run.variant, run.seed,
                 run.estimator_mode.empty() ? "-" : run.estimator_mode, run.steps.size(),
                 run.wall_time_s);
  if (run.frontend.enabled && !run.frontend.renderer.empty())  // what decides a rendered run's speed
    fmt::format_to(out, "Frames from: {}\n", run.frontend.renderer);
  if (!run.numerical_failure.message.empty())
    fmt::format_to(out, "NUMERICAL FAILURE, the results end before it: {}\n", run.numerical_failure.message);

  // Table 4: MSE per axis, then the error norm (RMS / max) per agent.
  fmt::format_to(out, "\nTable 4: position MSE [m^2]\n{:<{}}", "phase", nw);
  for (const std::string& a : run.agent_names) {
    for (const char* ax : {"X", "Y", "Z"}) {
      fmt::format_to(out, " {:>{}}", fmt::format("{} {}", a, ax), w);
    }
  }
  fmt::format_to(out, "\n");
  auto t4_row = [&](const std::string& name, const std::vector<AgentError>& agents) {
    fmt::format_to(out, "{:<{}}", name, nw);
    for (const AgentError& e : agents) {
      for (int i = 0; i < 3; ++i) fmt::format_to(out, " {}", cell(e.mse[i], w));
    }
    fmt::format_to(out, "\n");
  };
  for (const Table4Phase& row : m.table4.phases) t4_row(phase_name(run, row.phase), row.agents);
  t4_row("total", m.table4.total);

  fmt::format_to(out, "\nPosition error norm, RMS / max [m]\n{:<{}}", "phase", nw);
  for (const std::string& a : run.agent_names) {
    fmt::format_to(out, " {:>{}} {:>{}}", a + " rms", w, a + " max", w);
  }
  fmt::format_to(out, "\n");
  auto norm_row = [&](const std::string& name, const std::vector<AgentError>& agents) {
    fmt::format_to(out, "{:<{}}", name, nw);
    for (const AgentError& e : agents) {
      fmt::format_to(out, " {} {}", cell(e.rms_error, w, 3), cell(e.max_error, w, 3));
    }
    fmt::format_to(out, "\n");
  };
  for (const Table4Phase& row : m.table4.phases) norm_row(phase_name(run, row.phase), row.agents);
  norm_row("total", m.table4.total);

  fmt::format_to(out, "\nTable 5: landmark MSE [m^2], end of phase (total: end of run) / at init\n");
  fmt::format_to(out, "{:<{}} {:>6}", "phase", nw, "count");
  for (const char* h : {"fin X", "fin Y", "fin Z", "init X", "init Y", "init Z"}) {
    fmt::format_to(out, " {:>{}}", h, w);
  }
  fmt::format_to(out, "\n");
  auto t5_row = [&](const std::string& name, const LandmarkMse& l) {
    fmt::format_to(out, "{:<{}} {:>6}", name, nw, l.count);
    for (int i = 0; i < 3; ++i) fmt::format_to(out, " {}", cell(l.final_mse[i], w));
    for (int i = 0; i < 3; ++i) fmt::format_to(out, " {}", cell(l.init_mse[i], w));
    fmt::format_to(out, "\n");
  };
  for (std::size_t p = 0; p < m.table5.phases.size(); ++p) {
    t5_row(phase_name(run, static_cast<int>(p)), m.table5.phases[p]);
  }
  t5_row("total", m.table5.total);

  if (!m.table3.empty()) {
    std::size_t cw = 7;
    for (const OutlierRow& r : m.table3) cw = std::max(cw, r.counts.channel.size());
    const int cwi = static_cast<int>(cw);
    fmt::format_to(out, "\nTable 3: outliers (synthetic: corrupted by the source; rendered: > 3 px from the true projection)\n");
    fmt::format_to(out, "{:<{}} {:>10} {:>9} {:>9} {:>10} {:>10} {:>9}\n", "channel", cwi,
                   "corresp.", "injected", "outliers", "accepted", "out.acc.", "fraction");
    for (const OutlierRow& r : m.table3) {
      const OutlierCounts& c = r.counts;
      fmt::format_to(out, "{:<{}} {:>10} {:>9} {:>9} {:>10} {:>10} {}\n", c.channel, cwi,
                     c.correspondences, c.injected, c.outliers, c.accepted, c.outliers_accepted,
                     cell(r.accepted_outlier_fraction, 9));
    }
  }

  fmt::format_to(out, "\nNEES mean {} (dof {})", cell(m.nees.mean, 0, 3), m.nees.dof);
  for (std::size_t p = 0; p < m.nees.per_phase_mean.size(); ++p) {
    fmt::format_to(out, "{} {} {}", p == 0 ? "; per phase:" : ",",
                   phase_name(run, static_cast<int>(p)), cell(m.nees.per_phase_mean[p], 0, 3));
  }
  format_consistency(out, m.consistency);
  const Timings& t = m.timings_ms;
  fmt::format_to(out,
                 "\nStep time [ms]: mean {} (predict {}, update {}, init {}), median {}, p95 {}, "
                 "max {}\n",
                 cell(t.total.mean, 0, 3), cell(t.predict.mean, 0, 3), cell(t.update.mean, 0, 3),
                 cell(t.init.mean, 0, 3), cell(t.total.median, 0, 3), cell(t.total.p95, 0, 3),
                 cell(t.total.max, 0, 3));
  if (m.frontend.present) {
    fmt::format_to(out,
                   "Stages [ms/step, mean]: {} {}, detect {} (busy {}, partly behind rendering), "
                   "match {}, EKF {}, init {}\n",
                   run.frontend.frames_rendered ? "render" : "load frames", cell(t.render.mean, 0, 3), cell(t.detect.mean, 0, 3),
                   cell(m.frontend.detect_busy_ms_per_step, 0, 3), cell(t.match.mean, 0, 3),
                   cell(t.predict.mean + t.update.mean, 0, 3), cell(t.init.mean, 0, 3));
    const FrontendMetrics& f = m.frontend;
    fmt::format_to(out, "Lead detector: {} of {} frames in view ({}), error median {} px, p95 {} px, "
                   "{} false\n",
                   f.lead_detected, f.lead_in_view, cell(f.lead_detection_rate, 0, 3),
                   cell(f.lead_error_px.median, 0, 3), cell(f.lead_error_px.p95, 0, 3), f.lead_false);
    fmt::format_to(out, "Accepted tracked correspondences to their true projection: median {} px, p95 {} px\n",
                   cell(f.accepted_error_px.median, 0, 3), cell(f.accepted_error_px.p95, 0, 3));
    if (run.frontend.oracle_pixels)
      fmt::format_to(out, "ORACLE PIXELS (frontend.oracle_pixels): correct correspondences and lead "
                          "detections carried their exact projections; a diagnostic run, not the "
                          "frontend's figures\n");
  }
  fmt::format_to(out, "Landmarks: {} initialised, at most {} in the state\n",
                 m.landmarks.initialised, m.landmarks.max_in_state);
  fmt::format_to(out, "{}", format_formation_summary(m.formation, run));
  return fmt::to_string(b);
}

}  // namespace wingman::eval
