// EKF correction (paper eq. 43-45) for a batch of measurements whose Jacobians are a few dense
// blocks each. P H^T is built block by block (O(n m) instead of O(n^2 m)), and the covariance
// update P -= W W^T with W = P H^T L^-T (S = L L^T) is a symmetric rank-m update that keeps P
// exactly symmetric.
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

// Joint update with every measurement given (eq. 43-45). Returns false, leaving the state
// unchanged, when the innovation covariance is not positive definite.
bool ekf_update(FilterState& s, const std::vector<const Measurement*>& ms);

}  // namespace wingman::slam
