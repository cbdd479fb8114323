// FilterState's landmark slots with pixel offsets: where each camera's offset sits, and that
// removing or converting a landmark keeps every other slot's parameters and covariance.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <stdexcept>
#include <vector>

#include "slam/state.hpp"

using namespace wingman::slam;

namespace {
// P with distinct entries everywhere, so a misplaced row or column shows.
void fill_distinct(FilterState& s) {
  const int n = s.dim();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) A(r, c) = 0.01 * (r + 1) + 0.001 * (c + 1);
  s.P = A * A.transpose() + Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i) s.x(i) = i;
}
}  // namespace

TEST(FilterState, PixelOffsetsFollowTheAnchorCamera) {
  FilterState s(3);
  const int n0 = s.dim();
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(7), Eigen::MatrixXd::Zero(7, n0),
                 Eigen::MatrixXd::Identity(7, 7), {1, 0b101, 0.5});
  const LandmarkSlot& lm = s.landmarks().back();
  EXPECT_EQ(lm.dim(), 7);
  EXPECT_EQ(lm.pixel_offset(0), n0 + 3);
  EXPECT_EQ(lm.pixel_offset(1), -1);  // the anchor
  EXPECT_EQ(lm.pixel_offset(2), n0 + 5);
  EXPECT_EQ(lm.pixel_offset(3), -1);  // no such camera
  // Without an anchor there are none, and the sizes must match.
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(3), Eigen::MatrixXd::Zero(3, s.dim()),
                 Eigen::MatrixXd::Identity(3, 3));
  EXPECT_EQ(s.landmarks().back().pixel_offset(0), -1);
  EXPECT_THROW(s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(3),
                              Eigen::MatrixXd::Zero(3, s.dim()), Eigen::MatrixXd::Identity(3, 3), {0, 0b10, 0.5}),
               std::invalid_argument);
  EXPECT_THROW(s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(7),
                              Eigen::MatrixXd::Zero(7, s.dim()), Eigen::MatrixXd::Identity(7, 7), {3, 0b11, 0.5}),
               std::invalid_argument);
  // The anchor's own offsets, or a camera the team does not have, are refused.
  EXPECT_THROW(s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(5),
                              Eigen::MatrixXd::Zero(5, s.dim()), Eigen::MatrixXd::Identity(5, 5), {1, 0b10, 0.5}),
               std::invalid_argument);
  EXPECT_THROW(s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(5),
                              Eigen::MatrixXd::Zero(5, s.dim()), Eigen::MatrixXd::Identity(5, 5), {1, 0b1000, 0.5}),
               std::invalid_argument);
}

TEST(FilterState, RemovingAndConvertingKeepTheOtherSlotsWithTheirOffsets) {
  FilterState s(2);
  const int n0 = s.dim();
  s.add_landmark(LandmarkKind::InverseDepth, Eigen::VectorXd::Zero(8), Eigen::MatrixXd::Zero(8, n0),
                 Eigen::MatrixXd::Identity(8, 8), {0, 0b10, 0.5});
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(5), Eigen::MatrixXd::Zero(5, s.dim()),
                 Eigen::MatrixXd::Identity(5, 5), {1, 0b01, 0.5});
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(3), Eigen::MatrixXd::Zero(3, s.dim()),
                 Eigen::MatrixXd::Identity(3, 3));
  fill_distinct(s);
  const FilterState before = s;
  const LandmarkId idp = s.landmarks()[0].id, mid = s.landmarks()[1].id;

  // Converting the first (inverse depth, 6 + 2) leaves its offset and every later slot intact.
  Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();
  J.leftCols<3>().setIdentity();
  s.convert_to_euclidean(idp, Eigen::Vector3d(1, 2, 3), J);
  const LandmarkSlot& a = *s.find(idp);
  EXPECT_EQ(a.kind, LandmarkKind::Euclidean);
  EXPECT_EQ(a.dim(), 5);
  const int off_before = before.landmarks()[0].pixel_offset(1), off_now = a.pixel_offset(1);
  EXPECT_EQ(off_now, n0 + 3);
  EXPECT_EQ(s.x.segment<2>(off_now), before.x.segment<2>(off_before));
  EXPECT_LT((s.P.block<2, 2>(off_now, off_now) - before.P.block<2, 2>(off_before, off_before)).norm(), 1e-12);
  const LandmarkSlot& b = *s.find(mid);
  EXPECT_EQ(b.offset, before.landmarks()[1].offset - 3);
  EXPECT_EQ(s.x.tail(8), before.x.tail(8));

  // Removing the middle one (3 + 2) shifts the last by 5 and keeps its block.
  s.remove_landmark(mid);
  const LandmarkSlot& c = s.landmarks().back();
  EXPECT_EQ(c.offset, s.dim() - 3);
  EXPECT_EQ(s.x.tail(3), before.x.tail(3));
  EXPECT_LT((s.P.bottomRightCorner(3, 3) - before.P.bottomRightCorner(3, 3)).norm(), 1e-12);
  EXPECT_EQ(s.dim(), n0 + 5 + 3);
}

// An offset not yet a state is independent of everything, so stating it later is exact: the grown
// state holds every old entry where the old slots say, and the new pairs with their prior only.
TEST(FilterState, StatingPixelOffsetsKeepsEveryOtherEntryAndAddsOnlyTheirPrior) {
  FilterState s(4);
  const int n0 = s.dim();
  // Anchored in camera 1 with camera 3's offsets; anchored in camera 0 with none; no offsets.
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(5), Eigen::MatrixXd::Zero(5, n0),
                 Eigen::MatrixXd::Identity(5, 5), {1, 0b1000, 0.5});
  s.add_landmark(LandmarkKind::InverseDepth, Eigen::VectorXd::Zero(6), Eigen::MatrixXd::Zero(6, s.dim()),
                 Eigen::MatrixXd::Identity(6, 6), {0, 0, 2.0});
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(3), Eigen::MatrixXd::Zero(3, s.dim()),
                 Eigen::MatrixXd::Identity(3, 3));
  fill_distinct(s);
  const FilterState before = s;
  const LandmarkId a = s.landmarks()[0].id, b = s.landmarks()[1].id, c = s.landmarks()[2].id;
  EXPECT_DOUBLE_EQ(s.find(a)->unstated_offset_variance(0), 0.25);
  EXPECT_DOUBLE_EQ(s.find(a)->unstated_offset_variance(1), 0.0);  // the anchor
  EXPECT_DOUBLE_EQ(s.find(a)->unstated_offset_variance(3), 0.0);  // stated
  EXPECT_DOUBLE_EQ(s.find(c)->unstated_offset_variance(1), 0.0);  // no offsets

  // Camera 0 goes before camera 3 in a; b gains cameras 3 and 1 (asked twice, stated once);
  // the anchor, a landmark without offsets and an unknown id are skipped.
  s.state_pixel_offsets({{a, 0}, {b, 3}, {b, 1}, {b, 3}, {a, 1}, {c, 2}, {999, 1}});
  const LandmarkSlot &la = *s.find(a), &lb = *s.find(b), &lc = *s.find(c);
  EXPECT_EQ(s.dim(), before.dim() + 6);
  EXPECT_EQ(la.dim(), 7);
  EXPECT_EQ(la.pixel_offset(0), la.offset + 3);
  EXPECT_EQ(la.pixel_offset(3), la.offset + 5);
  EXPECT_EQ(lb.offset, la.offset + 7);
  EXPECT_EQ(lb.pixel_offset(1), lb.offset + 6);
  EXPECT_EQ(lb.pixel_offset(3), lb.offset + 8);
  EXPECT_EQ(lb.pixel_offset(2), -1);
  EXPECT_EQ(lc.offset, lb.offset + 10);

  // Old index -> new index, from the slots before and after.
  std::vector<int> to(before.dim());
  for (int i = 0; i < n0; ++i) to[i] = i;
  for (std::size_t k = 0; k < before.landmarks().size(); ++k) {
    const LandmarkSlot &o = before.landmarks()[k], &n = s.landmarks()[k];
    for (int i = 0; i < o.base_dim(); ++i) to[o.offset + i] = n.offset + i;
    for (int cam = 0; cam < 4; ++cam)
      if (o.pixel_offset(cam) >= 0)
        for (int i = 0; i < 2; ++i) to[o.pixel_offset(cam) + i] = n.pixel_offset(cam) + i;
  }
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(s.dim(), s.dim());
  Eigen::VectorXd x_expected = Eigen::VectorXd::Zero(s.dim());
  for (int r = 0; r < before.dim(); ++r) {
    x_expected(to[r]) = before.x(r);
    for (int col = 0; col < before.dim(); ++col) expected(to[r], to[col]) = before.P(r, col);
  }
  for (int i = 0; i < 2; ++i) {
    expected(la.pixel_offset(0) + i, la.pixel_offset(0) + i) = 0.25;
    expected(lb.pixel_offset(1) + i, lb.pixel_offset(1) + i) = 4.0;
    expected(lb.pixel_offset(3) + i, lb.pixel_offset(3) + i) = 4.0;
  }
  EXPECT_EQ(s.x, x_expected);
  EXPECT_EQ(s.P, expected);
  // Stating them again changes nothing.
  const FilterState once = s;
  s.state_pixel_offsets({{a, 0}, {b, 1}});
  EXPECT_EQ(s.P, once.P);
}
