// Nonlinear observability analysis of paper section 4 (eq. 10-32, Table 2, Fig. 4) and
// docs/design.md, the estimator: the observability matrix O = [d L^k_f h / dx], k = 0..K, for every measurement a
// sensor set feeds, its rank by SVD, its right null space (the unobservable modes) and which
// states those modes touch.
//
// The gradients come from the filter's own measurement builders (slam/measurement_models), never
// from a second copy of the models: along the constant-velocity flow of eq. 1 / 33,
// Phi(t, x) = x + t f(x) (exact, since f(x) = F x with F^2 = 0), so
//   d/dx L^k_f h(x) = d^k/dt^k [ H(Phi(t, x)) (I + t F) ]_{t=0} = H^(k)(0) + k H^(k-1)(0) F,
// where H(.) is the filter's analytic Jacobian and H^(k) its k-th derivative along the flow,
// taken by a high-order central finite-difference stencil in t (one variable, so it stays
// accurate to ~1e-10 relative for k <= 3; the report carries an estimate of that error).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/measurement_models.hpp"
#include "slam/state.hpp"

namespace wingman::slam {

// Which measurements are fed (Table 1 generalised): per UAV, whether it projects the lead
// (eq. 5), carries an altimeter (eq. 8) or a range sensor to the lead (eq. 9), and which
// landmarks it projects (eq. 4, indices into the state's landmarks); whether the lead has GPS (eq. 7).
struct SensorSet {
  std::vector<bool> sees_lead, altimeter, range;
  std::vector<std::vector<int>> visibility;
  bool gps = false;

  // n UAVs, nothing fed; every UAV sees all `landmarks` when `all_landmarks`.
  static SensorSet empty(int num_uavs, int num_landmarks, bool all_landmarks = true);
  int num_uavs() const { return static_cast<int>(sees_lead.size()); }
};

// Where O is evaluated: the agents' positions and velocities (cameras, as the filter holds
// them), the landmarks, and the camera rigs the filter would use.
struct EvaluationPoint {
  FilterState state{1};
  std::vector<CameraRig> rigs;
};

// Builds the filter state of eq. 2 (Euclidean landmarks) from its parts.
FilterState make_filter_state(const Eigen::Vector3d& lead_pos, const Eigen::Vector3d& lead_vel,
                              const std::vector<Eigen::Vector3d>& cam_pos,
                              const std::vector<Eigen::Vector3d>& cam_vel,
                              const std::vector<Eigen::Vector3d>& landmarks);

// A generic point (seeded): lead near the ground, UAVs 12-18 m above it with nadir cameras,
// landmarks on the ground below them, every velocity O(1 m/s) and random. Generic means no
// accidental coincidence (equal velocities, zero vertical speed) hides or adds a mode.
EvaluationPoint generic_point(int num_uavs, int num_landmarks, unsigned long seed);

// State names in layout order: lead.x, lead.vx, ..., uav1.x, ..., lm0.x, ... (UAVs from 1,
// landmarks from 0).
std::vector<std::string> state_names(const FilterState& s);

// Highest Lie order offered: beyond it the finite-difference rows lose too many digits.
inline constexpr int kMaxLieOrder = 5;

struct ObservabilityMatrix {
  // Row i is row_scale(i) * d(L^k h)/dx for one measurement component h at one order k; the
  // scale (T^k / |dh/dx| with T the time scale of the relative motion) only balances the rows.
  Eigen::MatrixXd O;
  Eigen::VectorXd row_scale;
  std::vector<std::string> rows;  // e.g. "L2 proj(uav1,lm3).u", orders 0..K in turn
  double derivative_error = 0;    // estimated relative error of the finite-difference rows
};

// Stacks the gradients of L^0..L^order of every fed measurement at `p`. Throws
// std::invalid_argument on an inconsistent sensor set or a point where a fed projection is
// behind its camera (the model is undefined there).
ObservabilityMatrix observability_matrix(const EvaluationPoint& p, const SensorSet& sensors,
                                         int order);

struct ObservabilityReport {
  int dim = 0, rank = 0;
  int unobservable_modes() const { return dim - rank; }
  double tolerance = 0;        // relative: sigma_i counts when sigma_i > tolerance * sigma_max
  double state_tolerance = 0;  // a state is observable when |N^T e_i| <= this
  Eigen::VectorXd singular_values;
  Eigen::MatrixXd null_space;  // dim x modes, orthonormal columns
  std::vector<std::string> names;
  std::vector<bool> observable;  // per state
};

// Rank and null space of O. `tolerance` is the relative singular-value threshold: at generic
// points the smallest genuine singular value is ~1e-3 of the largest and the rounding floor of
// the finite-difference rows ~1e-12 (derivative_error), so 1e-8 sits between them with margin.
ObservabilityReport analyse(const ObservabilityMatrix& m, const std::vector<std::string>& names,
                            double tolerance, double state_tolerance);

// The same null space in a readable basis (as the paper's eq. 32 writes it): each column is 1 at
// its own pivot state and 0 at the other columns' pivots (reduced echelon form, pivots the
// first states in layout order that the modes move independently).
Eigen::MatrixXd readable_basis(const Eigen::MatrixXd& N, std::vector<int>* pivots = nullptr);

// Largest principal angle (rad) between the column spaces of A and B (0 when they coincide).
double subspace_angle(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

}  // namespace wingman::slam
