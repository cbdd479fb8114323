#include "slam/ekf_update.hpp"

#include <Eigen/Cholesky>

namespace wingman::slam {

Eigen::MatrixXd covariance_times_jacobian(const FilterState& s, const Measurement& m) {
  Eigen::MatrixXd PHt = Eigen::MatrixXd::Zero(s.dim(), m.dim());
  for (const auto& b : m.blocks) PHt.noalias() += s.P.middleCols(b.col, b.H.cols()) * b.H.transpose();
  return PHt;
}

SmallSq innovation_covariance(const FilterState& s, const Measurement& m) {
  SmallSq S = m.R;
  if (m.camera >= 0) S.noalias() += m.orientation_sigma * m.orientation_sigma * m.V * m.V.transpose();
  for (const auto& a : m.blocks)
    for (const auto& b : m.blocks)
      S.noalias() += a.H * s.P.block(a.col, b.col, a.H.cols(), b.H.cols()) * b.H.transpose();
  return 0.5 * (S + S.transpose());
}

double mahalanobis_squared(const Measurement& m, const SmallSq& S) {
  const SmallVec y = m.innovation();
  return y.dot(S.ldlt().solve(y));
}

Eigen::VectorXd single_measurement_correction(const FilterState& s, const Measurement& m) {
  const Eigen::MatrixXd PHt = covariance_times_jacobian(s, m);
  const SmallSq S = innovation_covariance(s, m);
  const SmallVec w = S.ldlt().solve(m.innovation());
  return PHt * w;
}

bool ekf_update(FilterState& s, const std::vector<const Measurement*>& ms) {
  int rows = 0;
  for (const auto* m : ms) rows += m->dim();
  if (rows == 0) return true;
  const int n = s.dim();

  Eigen::MatrixXd PHt = Eigen::MatrixXd::Zero(n, rows);
  Eigen::VectorXd y(rows);
  int r = 0;
  for (const auto* m : ms) {
    for (const auto& b : m->blocks)
      PHt.middleCols(r, m->dim()).noalias() += s.P.middleCols(b.col, b.H.cols()) * b.H.transpose();
    y.segment(r, m->dim()) = m->innovation();
    r += m->dim();
  }
  // S = H (P H^T) + R, row block by row block.
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(rows, rows);
  r = 0;
  for (const auto* m : ms) {
    for (const auto& b : m->blocks)
      S.middleRows(r, m->dim()).noalias() += b.H * PHt.middleRows(b.col, b.H.cols());
    S.block(r, r, m->dim(), m->dim()) += m->R;
    r += m->dim();
  }
  // Shared gimbal noise: every pair of projections of one camera is correlated through it.
  std::vector<int> offsets;
  r = 0;
  for (const auto* m : ms) offsets.push_back(r), r += m->dim();
  for (size_t a = 0; a < ms.size(); ++a) {
    if (ms[a]->camera < 0) continue;
    for (size_t b = 0; b < ms.size(); ++b)
      if (ms[b]->camera == ms[a]->camera)
        S.block(offsets[a], offsets[b], ms[a]->dim(), ms[b]->dim()).noalias() +=
            ms[a]->orientation_sigma * ms[a]->orientation_sigma * ms[a]->V * ms[b]->V.transpose();
  }
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return false;

  // W^T = L^-1 (P H^T)^T, so K y = W L^-1 y and K S K^T = W W^T.
  const Eigen::MatrixXd Wt = llt.matrixL().solve(PHt.transpose());
  const Eigen::VectorXd v = llt.matrixL().solve(y);
  s.x.noalias() += Wt.transpose() * v;                                    // eq. 43
  s.P.selfadjointView<Eigen::Lower>().rankUpdate(Wt.transpose(), -1.0);  // eq. 44
  for (int c = 0; c < n; ++c) s.P.row(c).tail(n - c - 1) = s.P.col(c).tail(n - c - 1).transpose();
  return true;
}

}  // namespace wingman::slam
