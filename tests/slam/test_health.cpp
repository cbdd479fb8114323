// The per-step covariance check: every entry finite and P symmetric, across the tiles it walks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>
#include <string>

#include "slam/health.hpp"
#include "slam/state.hpp"

using namespace wingman::slam;

namespace {
// Two cameras and 60 Euclidean landmarks: 198 states, more than one tile of the check.
FilterState big_state() {
  FilterState s(2);
  for (int i = 0; i < 60; ++i)
    s.add_landmark(LandmarkKind::Euclidean, Eigen::Vector3d(i, 0, 0), Eigen::MatrixXd::Zero(3, s.dim()),
                   Eigen::Matrix3d::Identity());
  const int n = s.dim();
  const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(n, n, [n](Eigen::Index r, Eigen::Index c) {
    return std::sin(0.37 * static_cast<double>(r * n + c));
  });
  s.P = A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  return s;
}
std::string failure(const FilterState& s) {
  try {
    check_covariance(s, "the test");
  } catch (const NumericalFailure& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Health, CovarianceCheckFindsAsymmetryAndNonFiniteEntriesAnywhere) {
  const FilterState s = big_state();
  EXPECT_EQ(failure(s), "");
  // Far from the diagonal, in either triangle, in the last partial tile and the first.
  for (const auto& [r, c] : {std::pair{190, 3}, std::pair{3, 190}, std::pair{197, 130}, std::pair{1, 0}}) {
    FilterState t = s;
    t.P(r, c) += 1e-6;
    EXPECT_NE(failure(t).find("not symmetric"), std::string::npos) << r << ", " << c;
    t = s;
    t.P(r, c) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(failure(t).find("covariance nan"), std::string::npos) << r << ", " << c << ": " << failure(t);
  }
}
