// EKF correction (paper eq. 43-45) for a batch of measurements whose Jacobians are a few dense
// blocks each. The batch is processed in blocks whose noises are independent of each other's (a
// camera's projections when they share its gimbal's noise; otherwise 64 rows at a time), each
// linearised at the prior, so that the result is the joint update up to rounding while no large
// innovation covariance is factorised: O(n^2 m + n sum m_i^2 + sum m_i^3) for n states, m rows,
// m_i per block, against O(n^2 m + n m^2 + m^3) jointly. P H^T is built Jacobian block by
// Jacobian block (O(n m)), and the covariance update P -= W W^T with W = P H^T L^-T (S = L L^T)
// is a symmetric rank-m_i update (BLAS dsyrk) that keeps P exactly symmetric.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "slam/measurement_models.hpp"
#include "slam/state.hpp"

namespace wingman::slam {

// P H^T of one measurement (n x dim).
Eigen::MatrixXd covariance_times_jacobian(const FilterState& s, const Measurement& m);
// Innovation covariance S = H P H^T + R of one measurement.
SmallSq innovation_covariance(const FilterState& s, const Measurement& m);
// Squared Mahalanobis distance of the innovation.
double mahalanobis_squared(const Measurement& m, const SmallSq& S);
// State correction K y of one measurement, without touching P (1-point RANSAC hypotheses).
Eigen::VectorXd single_measurement_correction(const FilterState& s, const Measurement& m);

// Update with every measurement given (eq. 43-45). Returns false, leaving the state unchanged,
// when a block's innovation covariance is not positive definite.
bool ekf_update(FilterState& s, const std::vector<const Measurement*>& ms);

}  // namespace wingman::slam
