// Cross-UAV descriptor matching with epipolar and triangulation checks (see cross_match.hpp).
#include "vision/cross_match.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <stdexcept>
#include <string>

#include "geometry/bounds_check.hpp"

namespace wingman::vision {

namespace {
Eigen::Matrix3d skew3(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}
double focal(const geometry::PinholeCamera& c) { return 0.5 * (c.fx() + c.fy()); }
double line_distance(const Eigen::Vector3d& x, const Eigen::Vector3d& l) {
  const double n = std::hypot(l.x(), l.y());
  return n > 0 ? std::abs(x.dot(l)) / n : std::numeric_limits<double>::infinity();
}
}  // namespace

PairGeometry evaluate_pair(const Eigen::Vector2d& uv_a, const CameraView& a, const Eigen::Vector2d& uv_b,
                           const CameraView& b) {
  PairGeometry g;
  const Eigen::Vector2d na = a.camera.unproject_normalised(uv_a), nb = b.camera.unproject_normalised(uv_b);
  const Eigen::Vector3d xa(na.x(), na.y(), 1), xb(nb.x(), nb.y(), 1);

  // p_B = R_BA p_A + t_BA; E = [t_BA]x R_BA maps a's point to b's epipolar line.
  const Eigen::Matrix3d R_BA = b.pose.R_CW * a.pose.R_CW.transpose();
  const Eigen::Vector3d t_BA = b.pose.R_CW * (a.pose.position - b.pose.position);
  if (t_BA.norm() < 1e-9) {
    // No baseline: no epipolar geometry; the angle between the rays stands in for it.
    const double ang = std::acos(std::clamp((R_BA * xa).normalized().dot(xb.normalized()), -1.0, 1.0));
    g.epipolar_px = ang * focal(b.camera);
  } else {
    const Eigen::Matrix3d E = skew3(t_BA.normalized()) * R_BA;
    g.epipolar_px = std::max(line_distance(xb, E * xa) * focal(b.camera),
                             line_distance(xa, E.transpose() * xb) * focal(a.camera));
  }

  // DLT on normalised coordinates: x (P3 X) - P1 X = 0, y (P3 X) - P2 X = 0 for both cameras.
  Eigen::Matrix4d A;
  auto rows = [&](const CameraPose& pose, const Eigen::Vector2d& n, int r) {
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = pose.R_CW;
    P.col(3) = -pose.R_CW * pose.position;
    A.row(r) = n.x() * P.row(2) - P.row(0);
    A.row(r + 1) = n.y() * P.row(2) - P.row(1);
  };
  rows(a.pose, na, 0);
  rows(b.pose, nb, 2);
  for (int r = 0; r < 4; ++r) A.row(r).normalize();
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  if (std::abs(X(3)) < 1e-12 || !X.allFinite()) return g;
  g.triangulated = true;
  g.point_W = X.head<3>() / X(3);
  const Eigen::Vector3d pa = a.pose.to_camera(g.point_W), pb = b.pose.to_camera(g.point_W);
  g.depth_a = pa.z();
  g.depth_b = pb.z();
  const auto ua = a.camera.project(pa), ub = b.camera.project(pb);
  g.reprojection_px = (ua && ub) ? std::max((*ua - uv_a).norm(), (*ub - uv_b).norm())
                                 : std::numeric_limits<double>::infinity();
  const Eigen::Vector3d ra = g.point_W - a.pose.position, rb = g.point_W - b.pose.position;
  g.parallax_rad = std::acos(std::clamp(ra.normalized().dot(rb.normalized()), -1.0, 1.0));
  return g;
}

void CrossMatchSettings::validate() const {
  geometry::check_bounds(*this, "cross-match settings");
  // Limits of the fields no scenario key sets:
  auto bad = [](const std::string& what) { throw std::invalid_argument("cross-match settings: " + what); };
  if (min_depth < 0) bad("min_depth must be >= 0, got " + std::to_string(min_depth));
  if (min_parallax_deg < 0) bad("min_parallax_deg must be >= 0, got " + std::to_string(min_parallax_deg));
}

PairVerdict check_pair(const PairGeometry& g, const CrossMatchSettings& cfg) {
  if (!(g.epipolar_px <= cfg.max_epipolar_px)) return PairVerdict::Epipolar;
  if (!g.triangulated) return PairVerdict::NotTriangulated;
  if (!(g.depth_a >= cfg.min_depth && g.depth_b >= cfg.min_depth)) return PairVerdict::Depth;
  if (g.parallax_rad * 180.0 / std::numbers::pi < cfg.min_parallax_deg) return PairVerdict::Parallax;
  if (!(g.reprojection_px <= cfg.max_reprojection_px)) return PairVerdict::Reprojection;
  return PairVerdict::Accepted;
}

namespace {
// For each query row: best and second-best train rows (by distance).
struct Nearest {
  int best = -1;
  double d1 = std::numeric_limits<double>::infinity(), d2 = std::numeric_limits<double>::infinity();
};
std::vector<Nearest> nearest_two(const cv::Mat& q, const cv::Mat& t, int norm) {
  std::vector<Nearest> out(q.rows);
  if (q.empty() || t.empty()) return out;
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(norm, false).knnMatch(q, t, knn, 2);
  for (const auto& m : knn) {
    if (m.empty()) continue;
    Nearest& n = out[m[0].queryIdx];
    n.best = m[0].trainIdx;
    n.d1 = m[0].distance;
    if (m.size() > 1) n.d2 = m[1].distance;
  }
  return out;
}
cv::Mat gather(const cv::Mat& desc, const std::vector<int>& idx) {
  cv::Mat out(static_cast<int>(idx.size()), desc.cols, desc.type());
  for (int r = 0; r < out.rows; ++r) desc.row(idx[r]).copyTo(out.row(r));
  return out;
}
void check_indices(const std::vector<int>& idx, int n, const char* name) {
  for (int i : idx)
    if (i < 0 || i >= n)
      throw std::invalid_argument(std::string("match_across: ") + name + " holds keypoint " + std::to_string(i) +
                                  " of " + std::to_string(n));
}
}  // namespace

std::vector<int> all_keypoints(const Features& f) {
  std::vector<int> all(f.size());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

CrossMatchResult match_across(const Features& fa, const std::vector<int>& free_a, const CameraView& a,
                              const Features& fb, const std::vector<int>& free_b, const CameraView& b,
                              const CrossMatchSettings& cfg) {
  cfg.validate();
  if (fa.norm != fb.norm || fa.descriptors.type() != fb.descriptors.type() ||
      fa.descriptors.cols != fb.descriptors.cols)
    throw std::invalid_argument("match_across: the two cameras' descriptors are of different kinds");
  CrossMatchResult res;
  check_indices(free_a, fa.size(), "free_a");
  check_indices(free_b, fb.size(), "free_b");
  if (free_a.empty() || free_b.empty()) return res;
  const std::vector<int>& ia = free_a;
  const std::vector<int>& ib = free_b;
  const cv::Mat da = gather(fa.descriptors, ia), db = gather(fb.descriptors, ib);
  const double max_dist = cfg.max_distance > 0 ? cfg.max_distance : default_max_descriptor_distance(da);
  const auto ab = nearest_two(da, db, fa.norm), ba = nearest_two(db, da, fa.norm);

  for (int i = 0; i < static_cast<int>(ia.size()); ++i) {
    const int j = ab[i].best;
    if (j < 0 || ba[j].best != i) continue;  // mutual best
    if (ab[i].d1 > max_dist) continue;
    if (!(ab[i].d1 < cfg.ratio * ab[i].d2) || !(ba[j].d1 < cfg.ratio * ba[j].d2)) continue;
    ++res.descriptor_matches;
    CrossMatchCandidate c;
    c.keypoint_a = ia[i];
    c.keypoint_b = ib[j];
    c.uv_a = fa.pixel(c.keypoint_a);
    c.uv_b = fb.pixel(c.keypoint_b);
    c.distance = ab[i].d1;
    c.geometry = evaluate_pair(c.uv_a, a, c.uv_b, b);
    switch (check_pair(c.geometry, cfg)) {
      case PairVerdict::Accepted: res.matches.push_back(c); break;
      case PairVerdict::Epipolar: ++res.rejected_epipolar; break;
      case PairVerdict::NotTriangulated: ++res.rejected_triangulation; break;
      case PairVerdict::Depth: ++res.rejected_depth; break;
      case PairVerdict::Parallax: ++res.rejected_parallax; break;
      case PairVerdict::Reprojection: ++res.rejected_reprojection; break;
    }
  }
  std::stable_sort(res.matches.begin(), res.matches.end(),
                   [](const CrossMatchCandidate& x, const CrossMatchCandidate& y) {
                     if (x.distance != y.distance) return x.distance < y.distance;
                     return x.geometry.epipolar_px < y.geometry.epipolar_px;
                   });
  return res;
}

std::vector<CrossMatchCandidate> select_spread(const std::vector<CrossMatchCandidate>& matches, int needed,
                                               const geometry::PinholeCamera& cam_a,
                                               const std::vector<Eigen::Vector2d>& existing_a,
                                               const geometry::PinholeCamera& cam_b,
                                               const std::vector<Eigen::Vector2d>& existing_b,
                                               const SpreadSettings& cfg) {
  if (cfg.grid_cols < 1 || cfg.grid_rows < 1)
    throw std::invalid_argument("spread settings: grid must be at least 1 x 1, got " +
                                std::to_string(cfg.grid_cols) + " x " + std::to_string(cfg.grid_rows));
  if (cfg.min_separation_px < 0)
    throw std::invalid_argument("spread settings: min_separation_px must be >= 0, got " +
                                std::to_string(cfg.min_separation_px));
  std::vector<CrossMatchCandidate> out;
  if (needed <= 0) return out;
  const int cells = cfg.grid_cols * cfg.grid_rows;
  auto cell = [&](const geometry::PinholeCamera& c, const Eigen::Vector2d& uv) {
    const int x = std::clamp(static_cast<int>((uv.x() + 0.5) * cfg.grid_cols / c.width()), 0, cfg.grid_cols - 1);
    const int y = std::clamp(static_cast<int>((uv.y() + 0.5) * cfg.grid_rows / c.height()), 0, cfg.grid_rows - 1);
    return y * cfg.grid_cols + x;
  };
  std::vector<int> count_a(cells, 0), count_b(cells, 0);
  std::vector<Eigen::Vector2d> taken_a = existing_a, taken_b = existing_b;
  for (const auto& uv : existing_a) ++count_a[cell(cam_a, uv)];
  for (const auto& uv : existing_b) ++count_b[cell(cam_b, uv)];
  const double sep2 = cfg.min_separation_px * cfg.min_separation_px;
  auto clear_of = [&](const std::vector<Eigen::Vector2d>& taken, const Eigen::Vector2d& uv) {
    return std::none_of(taken.begin(), taken.end(),
                        [&](const Eigen::Vector2d& t) { return (t - uv).squaredNorm() < sep2; });
  };
  std::vector<bool> done(matches.size(), false);
  while (static_cast<int>(out.size()) < needed) {
    int pick = -1, pick_load = std::numeric_limits<int>::max();
    for (std::size_t m = 0; m < matches.size(); ++m) {
      if (done[m]) continue;
      const auto& c = matches[m];
      if (!clear_of(taken_a, c.uv_a) || !clear_of(taken_b, c.uv_b)) {
        done[m] = true;  // never becomes clear again
        continue;
      }
      const int load = count_a[cell(cam_a, c.uv_a)] + count_b[cell(cam_b, c.uv_b)];
      if (load < pick_load) {
        pick_load = load;
        pick = static_cast<int>(m);
      }
    }
    if (pick < 0) break;
    const auto& c = matches[pick];
    done[pick] = true;
    ++count_a[cell(cam_a, c.uv_a)];
    ++count_b[cell(cam_b, c.uv_b)];
    taken_a.push_back(c.uv_a);
    taken_b.push_back(c.uv_b);
    out.push_back(c);
  }
  return out;
}

}  // namespace wingman::vision
