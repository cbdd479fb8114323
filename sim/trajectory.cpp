#include "sim/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace wingman::sim {

namespace {

// Second derivatives M_i at the knots: the tridiagonal system of a C2 cubic spline, solved by the
// Thomas algorithm (one right-hand side per axis, as a Vector3d).
std::vector<Eigen::Vector3d> knot_accelerations(const std::vector<double>& t,
                                                const std::vector<Eigen::Vector3d>& p, SplineEnds ends) {
  const std::size_t n = t.size();
  std::vector<double> lo(n, 0), di(n, 1), up(n, 0);
  std::vector<Eigen::Vector3d> rhs(n, Eigen::Vector3d::Zero());
  auto h = [&](std::size_t i) { return t[i + 1] - t[i]; };
  auto slope = [&](std::size_t i) -> Eigen::Vector3d { return (p[i + 1] - p[i]) / h(i); };
  for (std::size_t i = 1; i + 1 < n; ++i) {
    lo[i] = h(i - 1);
    di[i] = 2 * (h(i - 1) + h(i));
    up[i] = h(i);
    rhs[i] = 6 * (slope(i) - slope(i - 1));
  }
  if (ends == SplineEnds::Rest) {  // p'(t_0) = p'(t_n) = 0
    di[0] = 2 * h(0);
    up[0] = h(0);
    rhs[0] = 6 * slope(0);
    lo[n - 1] = h(n - 2);
    di[n - 1] = 2 * h(n - 2);
    rhs[n - 1] = -6 * slope(n - 2);
  }  // natural: M_0 = M_n = 0, the identity rows already set
  for (std::size_t i = 1; i < n; ++i) {
    const double m = lo[i] / di[i - 1];
    di[i] -= m * up[i - 1];
    rhs[i] -= m * rhs[i - 1];
  }
  std::vector<Eigen::Vector3d> M(n);
  M[n - 1] = rhs[n - 1] / di[n - 1];
  for (std::size_t i = n - 1; i-- > 0;) M[i] = (rhs[i] - up[i] * M[i + 1]) / di[i];
  return M;
}

}  // namespace

SplinePath::SplinePath(const std::vector<TrajectorySample>& samples, SplineEnds ends) : samples_(samples) {
  if (samples.size() < 2) throw std::invalid_argument("a spline path needs at least two samples");
  std::vector<Eigen::Vector3d> p;
  for (const auto& s : samples) {
    if (!t_.empty() && !(s.t > t_.back())) throw std::invalid_argument("spline sample times must increase");
    t_.push_back(s.t);
    p.push_back(s.position);
  }
  const auto M = knot_accelerations(t_, p, ends);
  for (std::size_t i = 0; i + 1 < t_.size(); ++i) {
    const double h = t_[i + 1] - t_[i];
    a_.push_back(p[i]);
    b_.push_back((p[i + 1] - p[i]) / h - h * (2 * M[i] + M[i + 1]) / 6);
    c_.push_back(M[i] / 2);
    d_.push_back((M[i + 1] - M[i]) / (6 * h));
  }
}

std::size_t SplinePath::segment(double t) const {
  const auto after = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
  return std::min(static_cast<std::size_t>(std::max<std::ptrdiff_t>(after - 1, 0)), a_.size() - 1);
}

KinematicState SplinePath::at(double t) const {
  KinematicState k;
  // Before the first sample and after the last the path holds still; at either sample itself it
  // moves as the spline does (a natural end's velocity is not zero there).
  if (t < t_.front() || t > t_.back()) {
    k.position = t < t_.front() ? samples_.front().position : samples_.back().position;
    return k;
  }
  const std::size_t i = segment(t);
  const double s = t - t_[i];
  k.position = a_[i] + s * (b_[i] + s * (c_[i] + s * d_[i]));
  k.velocity = b_[i] + s * (2 * c_[i] + 3 * s * d_[i]);
  k.acceleration = 2 * c_[i] + 6 * s * d_[i];
  k.jerk = 6 * d_[i];
  return k;
}

std::optional<Eigen::Quaterniond> SplinePath::orientation(double t) const {
  if (!samples_.front().orientation) return std::nullopt;
  if (t <= t_.front()) return samples_.front().orientation;
  if (t >= t_.back()) return samples_.back().orientation;
  const std::size_t i = segment(t);
  const double f = (t - t_[i]) / (t_[i + 1] - t_[i]);
  return samples_[i].orientation->slerp(f, *samples_[i + 1].orientation);
}

std::optional<TrajectoryFormat> format_from_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".tum" || ext == ".txt") return TrajectoryFormat::Tum;
  if (ext == ".csv") return TrajectoryFormat::Csv;
  return std::nullopt;
}

namespace {

constexpr std::size_t kMaxTrajectoryBytes = std::size_t{256} << 20;

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> split_fields(const std::string& line, TrajectoryFormat f) {
  std::vector<std::string> out;
  if (f == TrajectoryFormat::Csv) {
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) out.push_back(trim(cell));
    if (!line.empty() && line.back() == ',') out.push_back("");
  } else {
    std::istringstream ss(line);
    std::string w;
    while (ss >> w) out.push_back(w);
  }
  return out;
}

std::optional<double> parse_number(const std::string& s) {
  double v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

// One data line as numbers; throws naming file:line and the column.
std::vector<double> parse_row(const std::vector<std::string>& fields, TrajectoryFormat f,
                              const std::string& where) {
  static const std::vector<std::string> tum = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  static const std::vector<std::string> csv = {"t", "x", "y", "z"};
  const auto& names = f == TrajectoryFormat::Tum ? tum : csv;
  if (fields.size() != names.size())
    throw TrajectoryFileError(fmt::format("{}: expected {} fields ({}), got {}", where, names.size(),
                                          fmt::join(names, f == TrajectoryFormat::Csv ? "," : " "), fields.size()));
  std::vector<double> v;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const auto x = parse_number(fields[i]);
    if (!x)
      throw TrajectoryFileError(fmt::format("{}: column {} ({}): '{}' is not a finite number", where, i + 1,
                                            names[i], fields[i].substr(0, 40)));
    v.push_back(*x);
  }
  return v;
}

TrajectorySample make_sample(const std::vector<double>& v, TrajectoryFormat f, const std::string& where) {
  TrajectorySample s;
  s.t = v[0];
  s.position = {v[1], v[2], v[3]};
  if (f == TrajectoryFormat::Tum) {
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1) > 1e-3)
      throw TrajectoryFileError(fmt::format("{}: quaternion (qx qy qz qw) has norm {:.6g}; expected a unit "
                                            "quaternion", where, q.norm()));
    s.orientation = q.normalized();
  }
  return s;
}

}  // namespace

std::vector<TrajectorySample> read_trajectory_file(const std::string& path, TrajectoryFormat format) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw TrajectoryFileError(path + ": file not found");
  if (std::filesystem::file_size(path, ec) > kMaxTrajectoryBytes)
    throw TrajectoryFileError(fmt::format("{}: larger than {} MiB", path, kMaxTrajectoryBytes >> 20));
  std::ifstream in(path);
  if (!in) throw TrajectoryFileError(path + ": cannot be read");
  std::vector<TrajectorySample> out;
  std::string line;
  bool header_seen = false;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string where = fmt::format("{}:{}", path, n);
    const std::string body = trim(line);
    if (body.empty() || body[0] == '#') continue;
    const auto fields = split_fields(body, format);
    // A CSV header: the first line that is not a comment, with no number in it.
    const bool header = format == TrajectoryFormat::Csv && out.empty() && !header_seen &&
                        std::none_of(fields.begin(), fields.end(), [](const std::string& x) { return parse_number(x).has_value(); });
    if (header) {
      header_seen = true;
      continue;
    }
    TrajectorySample s = make_sample(parse_row(fields, format, where), format, where);
    if (!out.empty() && !(s.t > out.back().t))
      throw TrajectoryFileError(fmt::format("{}: time {} is not after the previous sample's ({}); samples "
                                            "must be in increasing time order", where, s.t, out.back().t));
    out.push_back(s);
  }
  if (out.size() < 2)
    throw TrajectoryFileError(fmt::format("{}: {} samples; a trajectory needs at least two", path, out.size()));
  const double t0 = out.front().t;
  for (auto& s : out) s.t -= t0;
  return out;
}

}  // namespace wingman::sim
