#include "slam/state.hpp"

#include <algorithm>
#include <stdexcept>

#include "slam/inverse_depth.hpp"

namespace wingman::slam {

FilterState::FilterState(int num_cameras, bool gimbal_states, bool common_acceleration)
    : num_cameras_(num_cameras), gimbal_states_(gimbal_states), common_accel_(common_acceleration) {
  if (num_cameras < 1) throw std::invalid_argument("FilterState: at least one camera");
  x = Eigen::VectorXd::Zero(agent_dim());
  P = Eigen::MatrixXd::Zero(agent_dim(), agent_dim());
}

const LandmarkSlot* FilterState::find(LandmarkId id) const {
  // Slots are appended with increasing ids, so a binary search finds them.
  auto it = std::lower_bound(landmarks_.begin(), landmarks_.end(), id,
                             [](const LandmarkSlot& s, LandmarkId v) { return s.id < v; });
  return (it != landmarks_.end() && it->id == id) ? &*it : nullptr;
}

LandmarkId FilterState::add_landmark(LandmarkKind kind, const Eigen::VectorXd& value,
                                     const Eigen::MatrixXd& cross, const Eigen::MatrixXd& cov,
                                     int anchor_cam) {
  const int n = dim();
  const int d = static_cast<int>(value.size());
  if (anchor_cam >= num_cameras_)
    throw std::invalid_argument("FilterState::add_landmark: anchor camera out of range");
  const int extra = anchor_cam >= 0 ? 2 * (num_cameras_ - 1) : 0;
  if (d != (kind == LandmarkKind::Euclidean ? 3 : 6) + extra || cross.rows() != d || cross.cols() != n ||
      cov.rows() != d || cov.cols() != d)
    throw std::invalid_argument("FilterState::add_landmark: inconsistent sizes");
  x.conservativeResize(n + d);
  x.tail(d) = value;
  P.conservativeResize(n + d, n + d);
  P.block(n, 0, d, n) = cross;
  P.block(0, n, n, d) = cross.transpose();
  P.block(n, n, d, d) = 0.5 * (cov + cov.transpose());
  LandmarkSlot slot;
  slot.id = next_id_++;
  slot.kind = kind;
  slot.offset = n;
  slot.anchor_cam = anchor_cam;
  slot.extra = extra;
  landmarks_.push_back(slot);
  return slot.id;
}

void FilterState::remove_landmark(LandmarkId id) {
  auto it = std::find_if(landmarks_.begin(), landmarks_.end(),
                         [id](const LandmarkSlot& s) { return s.id == id; });
  if (it == landmarks_.end()) throw std::invalid_argument("FilterState::remove_landmark: unknown id");
  const int o = it->offset, d = it->dim(), n = dim(), tail = n - o - d;
  if (tail > 0) {
    x.segment(o, tail) = x.tail(tail).eval();
    P.block(o, 0, tail, n) = P.block(o + d, 0, tail, n).eval();
    P.block(0, o, n, tail) = P.block(0, o + d, n, tail).eval();
  }
  x.conservativeResize(n - d);
  P.conservativeResize(n - d, n - d);
  for (auto j = it + 1; j != landmarks_.end(); ++j) j->offset -= d;
  landmarks_.erase(it);
}

void FilterState::convert_to_euclidean(LandmarkId id, const Eigen::Vector3d& xyz,
                                       const Eigen::Matrix<double, 3, 6>& J) {
  auto it = std::find_if(landmarks_.begin(), landmarks_.end(),
                         [id](const LandmarkSlot& s) { return s.id == id; });
  if (it == landmarks_.end() || it->kind != LandmarkKind::InverseDepth)
    throw std::invalid_argument("FilterState::convert_to_euclidean: not an inverse-depth landmark");
  const int o = it->offset, n = dim();
  // New rows: J * P(y, :); the 3 surviving parameters take the first 3 slots of the 6.
  const Eigen::MatrixXd rows = J * P.middleRows(o, 6);          // 3 x n
  const Eigen::Matrix3d cov = rows.middleCols(o, 6) * J.transpose();
  x.segment<3>(o) = xyz;
  P.middleRows(o, 3) = rows;
  P.middleCols(o, 3) = rows.transpose();
  P.block<3, 3>(o, o) = 0.5 * (cov + cov.transpose());
  // Drop the last 3 parameters.
  const int tail = n - o - 6;
  if (tail > 0) {
    x.segment(o + 3, tail) = x.tail(tail).eval();
    P.block(o + 3, 0, tail, n) = P.block(o + 6, 0, tail, n).eval();
    P.block(0, o + 3, n, tail) = P.block(0, o + 6, n, tail).eval();
  }
  x.conservativeResize(n - 3);
  P.conservativeResize(n - 3, n - 3);
  it->kind = LandmarkKind::Euclidean;
  for (auto j = it + 1; j != landmarks_.end(); ++j) j->offset -= 3;
}

Eigen::Vector3d FilterState::landmark_position(const LandmarkSlot& s) const {
  if (s.kind == LandmarkKind::Euclidean) return x.segment<3>(s.offset);
  return inverse_depth_to_point(x.segment<6>(s.offset));
}

}  // namespace wingman::slam
