// FilterState's landmark slots with pixel offsets: where each camera's offset sits, and that
// removing or converting a landmark keeps every other slot's parameters and covariance.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <stdexcept>

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
                 Eigen::MatrixXd::Identity(7, 7), 1);
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
                              Eigen::MatrixXd::Zero(3, s.dim()), Eigen::MatrixXd::Identity(3, 3), 0),
               std::invalid_argument);
  EXPECT_THROW(s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(7),
                              Eigen::MatrixXd::Zero(7, s.dim()), Eigen::MatrixXd::Identity(7, 7), 3),
               std::invalid_argument);
}

TEST(FilterState, RemovingAndConvertingKeepTheOtherSlotsWithTheirOffsets) {
  FilterState s(2);
  const int n0 = s.dim();
  s.add_landmark(LandmarkKind::InverseDepth, Eigen::VectorXd::Zero(8), Eigen::MatrixXd::Zero(8, n0),
                 Eigen::MatrixXd::Identity(8, 8), 0);
  s.add_landmark(LandmarkKind::Euclidean, Eigen::VectorXd::Zero(5), Eigen::MatrixXd::Zero(5, s.dim()),
                 Eigen::MatrixXd::Identity(5, 5), 1);
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
