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
                                     const PixelOffsets& offsets) {
  const int n = dim();
  const int d = static_cast<int>(value.size());
  if (offsets.anchor_cam >= num_cameras_)
    throw std::invalid_argument("FilterState::add_landmark: anchor camera out of range");
  if (offsets.anchor_cam < 0 && offsets.cams != 0)
    throw std::invalid_argument("FilterState::add_landmark: pixel offsets without an anchor camera");
  if (offsets.anchor_cam >= 0 && num_cameras_ > 64)
    throw std::invalid_argument("FilterState::add_landmark: pixel offsets for at most 64 cameras");
  const std::uint64_t all = num_cameras_ >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << num_cameras_) - 1;
  if ((offsets.cams & ~all) != 0 || (offsets.anchor_cam >= 0 && (offsets.cams >> offsets.anchor_cam & 1)))
    throw std::invalid_argument("FilterState::add_landmark: offsets of a camera out of range or of the anchor");
  const int expected = (kind == LandmarkKind::Euclidean ? 3 : 6) + 2 * std::popcount(offsets.cams);
  if (d != expected || cross.rows() != d || cross.cols() != n || cov.rows() != d || cov.cols() != d)
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
  slot.offsets = offsets;
  landmarks_.push_back(slot);
  return slot.id;
}

void FilterState::state_pixel_offsets(const std::vector<std::pair<LandmarkId, int>>& pairs) {
  // New offsets per landmark (a camera asked for twice is stated once).
  std::vector<std::uint64_t> adding(landmarks_.size(), 0);
  int added = 0;
  for (const auto& [id, cam] : pairs) {
    const LandmarkSlot* lm = find(id);
    if (!lm || cam >= num_cameras_ || !(lm->unstated_offset_variance(cam) > 0)) continue;
    std::uint64_t& a = adding[lm - landmarks_.data()];
    if (!(a >> cam & 1)) ++added;
    a |= std::uint64_t{1} << cam;
  }
  if (added == 0) return;
  // Runs of the old state that stay contiguous, and where each lands; the new offsets go
  // between them, each camera's pair at its place in camera order within its landmark.
  struct Run { int from, to, len; };
  struct NewPair { int at; double var; };
  std::vector<Run> runs;
  std::vector<NewPair> fresh;
  const int n = dim(), n_new = n + 2 * added;
  int from = 0, shift = 0;
  for (std::size_t i = 0; i < landmarks_.size(); ++i) {
    LandmarkSlot& lm = landmarks_[i];
    const int base_end = lm.offset + lm.base_dim();
    lm.offset += shift;
    for (std::uint64_t rest = adding[i]; rest != 0; rest &= rest - 1) {
      const int cam = std::countr_zero(rest);
      // Old index where camera cam's pair goes: after the stated ones of lower cameras.
      const int at = base_end + 2 * std::popcount(lm.offsets.cams & ((std::uint64_t{1} << cam) - 1));
      runs.push_back({from, from + shift, at - from});
      fresh.push_back({at + shift, lm.offsets.sigma * lm.offsets.sigma});
      from = at;
      shift += 2;
    }
    lm.offsets.cams |= adding[i];
  }
  runs.push_back({from, from + shift, n - from});

  Eigen::VectorXd x_new = Eigen::VectorXd::Zero(n_new);
  Eigen::MatrixXd P_new = Eigen::MatrixXd::Zero(n_new, n_new);
  for (const Run& c : runs) {
    x_new.segment(c.to, c.len) = x.segment(c.from, c.len);
    for (const Run& r : runs) P_new.block(r.to, c.to, r.len, c.len) = P.block(r.from, c.from, r.len, c.len);
  }
  for (const NewPair& f : fresh) P_new.block<2, 2>(f.at, f.at).diagonal().setConstant(f.var);
  x = std::move(x_new);
  P = std::move(P_new);
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
