// Observability analysis (paper section 4.2, Table 2, Fig. 4): rank and null space of the
// Lie-derivative observability matrix for the Table 1 configurations and for each minimum
// condition of Fig. 4 removed; and the Lie-derivative rows checked against plain numerical
// differentiation of the filter's own measurement values.
#include <gtest/gtest.h>

#include <cmath>

#include "../numdiff.hpp"
#include "slam/observability.hpp"

namespace wingman::slam {
namespace {

constexpr double kTol = 1e-8, kStateTol = 1e-6;

// Table 1 presets for n2 UAVs: Quad 1 sees the lead and carries the altimeter and the range sensor.
SensorSet config(int c, int n2, int n1, bool gps) {
  SensorSet s = SensorSet::empty(n2, n1);
  s.sees_lead[0] = c != 2;
  s.altimeter[0] = s.range[0] = c != 1;
  s.gps = gps;
  return s;
}

ObservabilityReport report(const EvaluationPoint& p, const SensorSet& s, int order = 1) {
  return analyse(observability_matrix(p, s, order), state_names(p.state), kTol, kStateTol);
}

int modes(const SensorSet& s, int n1, int order = 1, unsigned long seed = 1) {
  return report(generic_point(2, n1, seed), s, order).unobservable_modes();
}

// A global translation along axis `a` (0 = x): 1 on that coordinate of every position.
Eigen::VectorXd translation(const FilterState& st, int a) {
  Eigen::VectorXd t = Eigen::VectorXd::Zero(st.dim());
  t(FilterState::lead_pos() + a) = 1;
  for (int j = 0; j < st.num_cameras(); ++j) t(FilterState::cam_pos(j) + a) = 1;
  for (const auto& lm : st.landmarks()) t(lm.offset + a) = 1;
  return t;
}

TEST(Observability, DimensionIsThreeN1PlusSixN2PlusSix) {
  for (int n1 : {2, 5, 9}) {
    const EvaluationPoint p = generic_point(3, n1, 4);
    EXPECT_EQ(report(p, config(1, 3, n1, true)).dim, 3 * n1 + 6 * 3 + 6);
  }
}

TEST(Observability, ConfigurationsOneAndTwoWithGpsAreFullRank) {
  for (int n1 : {2, 3, 6, 10})
    for (int c : {1, 2}) {
      const ObservabilityReport r = report(generic_point(2, n1, 7), config(c, 2, n1, true));
      EXPECT_EQ(r.rank, 3 * n1 + 6 * 2 + 6) << "config " << c << ", " << n1 << " landmarks";
      EXPECT_EQ(r.unobservable_modes(), 0);
      for (bool o : r.observable) EXPECT_TRUE(o);
    }
}

TEST(Observability, ConfigurationThreeWithoutGpsHasExactlyTheHorizontalTranslations) {
  for (int n1 : {2, 4, 6, 12})
    for (int order : {1, 2, 3}) {
      const EvaluationPoint p = generic_point(2, n1, 11);
      const ObservabilityReport r = report(p, config(3, 2, n1, false), order);
      ASSERT_EQ(r.unobservable_modes(), 2) << n1 << " landmarks, order " << order;
      Eigen::MatrixXd T(r.dim, 2);
      T << translation(p.state, 0), translation(p.state, 1);
      EXPECT_LT(subspace_angle(r.null_space, T), kStateTol) << n1 << " landmarks, order " << order;
      // Unobservable: exactly the x and y of every position (eq. 32).
      for (int i = 0; i < r.dim; ++i)
        EXPECT_EQ(r.observable[static_cast<std::size_t>(i)], T.row(i).norm() == 0) << r.names[static_cast<std::size_t>(i)];
    }
}

TEST(Observability, CountsDoNotDependOnTheGenericPoint) {
  for (unsigned long seed : {2ul, 3ul, 5ul, 8ul, 13ul}) {
    EXPECT_EQ(modes(config(3, 2, 5, false), 5, 1, seed), 2) << seed;
    EXPECT_EQ(modes(config(1, 2, 5, true), 5, 1, seed), 0) << seed;
    EXPECT_EQ(modes(config(2, 2, 5, false), 5, 2, seed), 5) << seed;
  }
}

// Fig. 4's minimum conditions: removing any one lowers the rank.
TEST(Observability, RemovingSharedLandmarksLowersTheRank) {
  const int n1 = 6;
  for (int c : {1, 2, 3}) {
    SensorSet s = config(c, 2, n1, c != 3);
    const int full = modes(s, n1);
    s.visibility = {{0, 1, 2}, {3, 4, 5}};  // nothing shared
    EXPECT_GT(modes(s, n1), full) << "config " << c;
  }
  // Two shared landmarks suffice; one leaves UAV 2 and its landmarks a free scale about it.
  SensorSet s = config(3, 2, n1, false);
  s.visibility = {{0, 1, 2, 3}, {2, 3, 4, 5}};
  EXPECT_EQ(modes(s, n1), 2);
  s.visibility = {{0, 1, 2, 3}, {3, 4, 5}};
  EXPECT_EQ(modes(s, n1), 3);
}

TEST(Observability, RemovingTheLeadObservationLowersTheRank) {
  const int n1 = 6;
  for (int c : {1, 3}) {
    SensorSet s = config(c, 2, n1, c == 1);
    const int full = modes(s, n1);
    s.sees_lead[0] = false;
    EXPECT_GT(modes(s, n1), full) << "config " << c;
  }
}

TEST(Observability, RemovingTheRangeOrTheAltimeterLowersTheRank) {
  const int n1 = 6;
  for (int c : {2, 3}) {
    for (int order : {1, 2}) {
      SensorSet s = config(c, 2, n1, c == 2);
      const int full = modes(s, n1, order);
      SensorSet no_range = s, no_alt = s;
      no_range.range[0] = false;
      no_alt.altimeter[0] = false;
      EXPECT_GT(modes(no_range, n1, order), full) << "config " << c << ", order " << order;
      EXPECT_GT(modes(no_alt, n1, order), full) << "config " << c << ", order " << order;
    }
  }
  // Section 4.2: with two UAVs seeing the lead, configuration 3 needs no range.
  SensorSet s = config(3, 2, n1, false);
  s.range[0] = false;
  s.sees_lead = {true, true};
  EXPECT_EQ(modes(s, n1), 2);
}

// The counts docs/observability.md explains, at Lie orders 1, 2, 3 (no GPS).
TEST(Observability, ModeCountsWithoutGpsFollowTheSymmetries) {
  const int n1 = 6;
  // Config 1: translation (3) + scale (1) + the lead's distance along Quad 1's ray (1), plus its
  // radial speed at order 1. Two UAVs seeing the lead triangulate it: the paper's 4.
  EXPECT_EQ(modes(config(1, 2, n1, false), n1, 1), 6);
  EXPECT_EQ(modes(config(1, 2, n1, false), n1, 2), 5);
  EXPECT_EQ(modes(config(1, 2, n1, false), n1, 3), 5);
  SensorSet two = config(1, 2, n1, false);
  two.sees_lead = {true, true};
  EXPECT_EQ(modes(two, n1, 2), 4);
  // Config 2: x, y translation (2) + the lead's relative state up to rotation about Quad 1:
  // 6 - 2 at order 1 (range, range rate), 6 - 3 from order 2 (|v_rel|^2 appears).
  EXPECT_EQ(modes(config(2, 2, n1, false), n1, 1), 6);
  EXPECT_EQ(modes(config(2, 2, n1, false), n1, 2), 5);
  EXPECT_EQ(modes(config(2, 2, n1, false), n1, 3), 5);
  // Order 0 sees no velocity at all.
  EXPECT_EQ(modes(config(3, 2, n1, false), n1, 0), 12);
}

TEST(Observability, LevelFlightOfTheAltimeterUavLeavesScaleUnobservable) {
  // The altimeter breaks the scale about Quad 1's height only through its vertical speed.
  EvaluationPoint p = generic_point(2, 6, 1);
  EXPECT_EQ(report(p, config(3, 2, 6, false), 2).unobservable_modes(), 2);
  p.state.x(FilterState::cam_vel(0) + 2) = 0;
  EXPECT_EQ(report(p, config(3, 2, 6, false), 2).unobservable_modes(), 3);
}

// The rows are gradients of Lie derivatives of the filter's own h: compare with plain numerical
// differentiation of L^k h(x) = d^k/dt^k h(x + t f(x)), from the builders' predicted values.
TEST(Observability, RowsMatchNestedNumericalDifferentiationOfTheFilterModels) {
  const int n1 = 3;
  const EvaluationPoint p = generic_point(2, n1, 21);
  const SensorSet s = config(3, 2, n1, true);
  const int order = 2;
  const ObservabilityMatrix om = observability_matrix(p, s, order);
  const int rows = static_cast<int>(om.O.rows()) / (order + 1);

  // All measurement values, stacked in the same order as the rows of O.
  const auto values = [&](const Eigen::VectorXd& x) {
    FilterState st = p.state;
    st.x = x;
    Eigen::VectorXd h(rows);
    int r = 0;
    for (int j = 0; j < 2; ++j) {
      const CameraRig& rig = p.rigs[static_cast<std::size_t>(j)];
      for (int i : s.visibility[static_cast<std::size_t>(j)]) {
        const LandmarkSlot& lm = st.landmarks()[static_cast<std::size_t>(i)];
        h.segment(r, 2) = landmark_measurement(st, lm, j, rig, Eigen::Vector2d::Zero(), 1)->h;
        r += 2;
      }
      if (s.sees_lead[static_cast<std::size_t>(j)]) {
        h.segment(r, 2) = lead_projection_measurement(st, j, rig, Eigen::Vector2d::Zero(), 1)->h;
        r += 2;
      }
      if (s.altimeter[static_cast<std::size_t>(j)]) h(r++) = altimeter_measurement(st, j, rig, 0, 1).h(0);
      if (s.range[static_cast<std::size_t>(j)]) h(r++) = range_measurement(st, j, rig, 0, 1).h(0);
    }
    h.segment(r, 3) = gps_measurement(st, Eigen::Vector3d::Zero(), 1).h;
    return h;
  };
  // f(x) of eq. 1: positions move with their velocities.
  const auto drift = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
    for (int a = 0; a <= 2; ++a) {
      const int pos = a == 0 ? FilterState::lead_pos() : FilterState::cam_pos(a - 1);
      f.segment<3>(pos) = x.segment<3>(pos + 3);
    }
    return f;
  };
  // L^1 and L^2 by 5-point differences in t, each then differentiated in x.
  const double ht = 0.05;
  const auto lie = [&](int k) {
    return [&, k](const Eigen::VectorXd& x) -> Eigen::VectorXd {
      const Eigen::VectorXd f = drift(x);
      const auto g = [&](double t) { return values(x + t * f); };
      if (k == 1) return (-g(2 * ht) + 8 * g(ht) - 8 * g(-ht) + g(-2 * ht)) / (12 * ht);
      return (-g(2 * ht) + 16 * g(ht) - 30 * g(0) + 16 * g(-ht) - g(-2 * ht)) / (12 * ht * ht);
    };
  };
  for (int k = 0; k <= order; ++k) {
    const Eigen::MatrixXd num =
        k == 0 ? testing::numerical_jacobian(values, p.state.x)
               : testing::numerical_jacobian(lie(k), p.state.x, 1e-4);
    const Eigen::MatrixXd ours =
        om.row_scale.segment(k * rows, rows).cwiseInverse().asDiagonal() * om.O.middleRows(k * rows, rows);
    for (int r = 0; r < rows; ++r) {
      const double scale = std::max(1.0, ours.row(r).norm());
      EXPECT_LT((ours.row(r) - num.row(r)).norm() / scale, k == 0 ? 1e-6 : 1e-4)
          << om.rows[static_cast<std::size_t>(k * rows + r)];
    }
  }
  EXPECT_LT(om.derivative_error, 1e-9);
}

TEST(Observability, RejectsInconsistentSensorSets) {
  const EvaluationPoint p = generic_point(2, 3, 1);
  SensorSet s = config(3, 2, 3, false);
  s.visibility[1] = {0, 3};  // no landmark 3
  EXPECT_THROW(observability_matrix(p, s, 1), std::invalid_argument);
  EXPECT_THROW(observability_matrix(p, config(3, 3, 3, false), 1), std::invalid_argument);
  EXPECT_THROW(observability_matrix(p, config(3, 2, 3, false), kMaxLieOrder + 1), std::invalid_argument);
}

TEST(Observability, ReadableBasisIsOneAtItsPivots) {
  const EvaluationPoint p = generic_point(2, 4, 3);
  const ObservabilityReport r = report(p, config(3, 2, 4, false));
  std::vector<int> piv;
  const Eigen::MatrixXd B = readable_basis(r.null_space, &piv);
  ASSERT_EQ(piv.size(), 2u);
  EXPECT_EQ(r.names[static_cast<std::size_t>(piv[0])], "lead.x");
  EXPECT_EQ(r.names[static_cast<std::size_t>(piv[1])], "lead.y");
  EXPECT_LT((B.col(0) - translation(p.state, 0)).norm(), 1e-8);
  EXPECT_LT((B.col(1) - translation(p.state, 1)).norm(), 1e-8);
}

}  // namespace
}  // namespace wingman::slam
