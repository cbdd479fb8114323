// A lead's path through timed positions (waypoints of a scenario, or the samples of a TUM or CSV
// trajectory file): a cubic spline per axis, so that position, velocity and acceleration are
// continuous and every derivative comes from the same curve analytically (docs/scenario.md,
// trajectories). The file readers name file:line for every malformed line.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::sim {

struct KinematicState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
  // The curve's second derivative (an IMU's specific force comes from it); zero where a truth
  // does not know it (the closed loop's discrete steps).
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
  // The third derivative, for the turn rate of a formation that turns with the lead.
  Eigen::Vector3d jerk = Eigen::Vector3d::Zero();
};

// One timed position; orientation only where the source has one (TUM).
struct TrajectorySample {
  double t = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Quaterniond> orientation;  // q_WB
};

// The `waypoints` of a scenario's lead trajectory: [t, x, y, z] rows in increasing time order
// (the reader checks the order, naming the row's line).
struct Waypoints {
  std::vector<Eigen::Vector4d> rows;
};

// A file path that may be empty (no file): a trajectory other than `file` prints it as "".
struct OptionalPath {
  std::string value;
  bool empty() const { return value.empty(); }
};

// How the spline ends: at rest (zero velocity at the first and last sample, so that waiting
// there before and after is smooth) or natural (zero acceleration there).
enum class SplineEnds { Rest, Natural };

// C2 cubic spline through the samples' positions (strictly increasing times, at least two).
// Before the first time and after the last the path holds that sample's position.
class SplinePath {
 public:
  SplinePath(const std::vector<TrajectorySample>& samples, SplineEnds ends);
  KinematicState at(double t) const;
  const std::vector<TrajectorySample>& samples() const { return samples_; }
  // The samples' orientation at t (spherical interpolation between samples), if they have one.
  std::optional<Eigen::Quaterniond> orientation(double t) const;

 private:
  std::vector<TrajectorySample> samples_;
  // The segment [t_i, t_i+1] holding t, for t within the samples' times.
  std::size_t segment(double t) const;

  std::vector<double> t_;
  // Per segment i: p(t) = a + b s + c s^2 + d s^3 with s = t - t_i.
  std::vector<Eigen::Vector3d> a_, b_, c_, d_;
};

// A malformed trajectory file: "<file>:<line>: what".
class TrajectoryFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class TrajectoryFormat { Tum, Csv };
// tum for .tum and .txt, csv for .csv; nullopt otherwise.
std::optional<TrajectoryFormat> format_from_extension(const std::string& path);

// TUM: "timestamp tx ty tz qx qy qz qw" per line, '#' comments and blank lines skipped.
// CSV: "t,x,y,z" per line, an optional header line whose first field is not a number.
// Times strictly increasing; shifted so that the first sample is at t = 0.
std::vector<TrajectorySample> read_trajectory_file(const std::string& path, TrajectoryFormat format);

}  // namespace wingman::sim
