// Central-difference Jacobians for checking analytic ones (as Ceres' and Sophus' tests do).
#pragma once

#include <Eigen/Core>
#include <functional>

namespace wingman::testing {

inline Eigen::MatrixXd numerical_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                          const Eigen::VectorXd& x, double h = 1e-6) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    J.col(i) = (f(xp) - f(xm)) / (2 * h);
  }
  return J;
}

}  // namespace wingman::testing
