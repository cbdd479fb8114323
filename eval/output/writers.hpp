// Writes a run's results in formats other tools read (docs/design.md, files): metrics.json, TUM
// trajectories, per-step and landmark CSVs, the map as PLY, and a fixed-width summary for
// stdout. NaN is written as JSON null and as an empty CSV field. All writers throw
// std::runtime_error naming the file if it cannot be written.
#pragma once

#include <filesystem>
#include <string>

#include "eval/metrics/metrics.hpp"
#include "eval/metrics/run_record.hpp"

namespace wingman::eval {

// metrics.json's layout version: a reader (wingman check) refuses files of another one. Raised
// whenever a key is renamed, removed or changes meaning; adding a key keeps it.
inline constexpr int kMetricsSchemaVersion = 2;

// Every table of compute_metrics plus the scenario, phases and software version, headed by
// schema_version and conventions (units, axis order, histogram bins).
void write_metrics_json(const Metrics& metrics, const RunRecord& run,
                        const std::filesystem::path& path);

// <dir>/<agent>.est.tum and <dir>/<agent>.gt.tum for every agent, one line per step:
// "timestamp tx ty tz qx qy qz qw" in seconds, q the agent's orientation (AgentStep::q_true/q_est).
void write_tum_trajectories(const RunRecord& run, const std::filesystem::path& dir);

// One row per step: k, t, phase, per-agent truth/estimate/sigma, NEES, map and timing columns.
void write_steps_csv(const RunRecord& run, const std::filesystem::path& path);

// One row per initialised landmark: truth, estimates at init / phase end / end, origin.
void write_landmarks_csv(const RunRecord& run, const std::filesystem::path& path);

// One row per tracked correspondence offered to the filter (rendered mode, when recorded):
// k, t, cam, landmark, u, v, true_u, true_v (empty when the landmark has no truth), outlier,
// accepted. write_results writes it only when the run recorded them.
void write_correspondences_csv(const RunRecord& run, const std::filesystem::path& path);
// lead.csv: every camera frame's lead detection (u, v; empty when none) beside the lead's truth
// (x_h's projection, distance, visible share, the visible pixels' box; empty in a replay of a
// dataset without labels).
void write_lead_csv(const RunRecord& run, const std::filesystem::path& path);

// ASCII PLY of the landmarks still in the map at the end (t_removed NaN): their final
// estimates coloured by origin (MapPoints::estimate), or their truth points (MapPoints::truth).
enum class MapPoints { estimate, truth };
void write_map_ply(const RunRecord& run, const std::filesystem::path& path, MapPoints which);

// Everything above into a results directory: metrics.json, traj/, steps.csv, landmarks.csv,
// map.ply, map_truth.ply, and formation.csv in closed loop. Plots are separate (plots.hpp) because they need gnuplot.
void write_results(const Metrics& metrics, const RunRecord& run,
                   const std::filesystem::path& dir);

// Readable fixed-width tables (Table 4, 5, 3, NEES, timings, map size, and the formation errors
// in closed loop) for stdout.
std::string format_summary(const Metrics& metrics, const RunRecord& run);

}  // namespace wingman::eval
