#include "slam/ekf_update.hpp"

#include <cblas.h>

#include <Eigen/Cholesky>
#include <algorithm>

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

namespace {
// Rows per block of measurements whose noises are independent: small enough that the solves
// (n m_i^2) stay well below the downdate (n^2 m), large enough for BLAS to run at speed.
constexpr int kIndependentRows = 64;

// The measurements in groups whose noises are independent of each other's, in the order they
// first appear: one group per camera whose projections share the gimbal's pointing error (eq. 45),
// and every other measurement in groups of at most kIndependentRows rows.
std::vector<std::vector<const Measurement*>> independent_blocks(const std::vector<const Measurement*>& ms) {
  std::vector<std::vector<const Measurement*>> out;
  std::vector<std::pair<int, std::size_t>> camera_group;  // camera, index in out
  int open = -1, open_rows = 0;                            // the group filling with independent rows
  for (const auto* m : ms) {
    if (m->camera >= 0) {
      auto it = std::find_if(camera_group.begin(), camera_group.end(), [&](const auto& g) { return g.first == m->camera; });
      if (it == camera_group.end()) {
        camera_group.emplace_back(m->camera, out.size());
        out.emplace_back();
        it = camera_group.end() - 1;
      }
      out[it->second].push_back(m);
      continue;
    }
    if (open < 0 || open_rows + m->dim() > kIndependentRows) {
      open = static_cast<int>(out.size());
      open_rows = 0;
      out.emplace_back();
    }
    out[open].push_back(m);
    open_rows += m->dim();
  }
  return out;
}

// out += P(:, col..) H^T with P read from its lower triangle only (the upper one is stale between
// blocks): column c of P is P(c, 0:c)^T above the diagonal and P(c:n, c) from it down.
void add_symmetric_columns_times(const Eigen::MatrixXd& P, int col, const SmallMat& H,
                                 Eigen::Ref<Eigen::MatrixXd> out) {
  const int n = static_cast<int>(P.rows());
  for (int k = 0; k < H.cols(); ++k) {
    const int c = col + k;
    out.topRows(c).noalias() += P.row(c).head(c).transpose() * H.col(k).transpose();
    out.bottomRows(n - c).noalias() += P.col(c).tail(n - c) * H.col(k).transpose();
  }
}

// Copies P's strictly lower triangle onto the upper one (to_upper) or the upper onto the lower,
// in square tiles so that both sides are read and written a cache line at a time.
void mirror_triangle(Eigen::MatrixXd& P, bool to_upper) {
  constexpr int kTile = 64;
  const int n = static_cast<int>(P.rows());
  for (int j0 = 0; j0 < n; j0 += kTile)
    for (int i0 = j0; i0 < n; i0 += kTile) {  // the tile at rows i0, columns j0 of the lower triangle
      const int h = std::min(kTile, n - i0), w = std::min(kTile, n - j0);
      if (i0 != j0) {
        if (to_upper) P.block(j0, i0, w, h) = P.block(i0, j0, h, w).transpose();
        else P.block(i0, j0, h, w) = P.block(j0, i0, w, h).transpose();
        continue;
      }
      for (int c = 0; c < w; ++c)
        for (int r = c + 1; r < h; ++r) {
          if (to_upper) P(j0 + c, i0 + r) = P(i0 + r, j0 + c);
          else P(i0 + r, j0 + c) = P(j0 + c, i0 + r);
        }
    }
}

// One block's correction, its Jacobians taken at the prior x0: the innovation is moved by what
// the earlier blocks corrected (y - H (x - x0)), so that the blocks in turn give the joint
// posterior of eq. 43-45 up to rounding. Only P's lower triangle (diagonal included) is read and
// written. W: n x rows of workspace.
bool block_update(FilterState& s, const std::vector<const Measurement*>& ms, const Eigen::VectorXd& x0,
                  Eigen::Ref<Eigen::MatrixXd> W) {
  const int rows = static_cast<int>(W.cols());
  W.setZero();  // P H^T first, then W = P H^T L^-T in place
  Eigen::VectorXd y(rows);
  const Eigen::VectorXd dx = s.x - x0;
  int r = 0;
  for (const auto* m : ms) {
    y.segment(r, m->dim()) = m->innovation();
    for (const auto& b : m->blocks) {
      add_symmetric_columns_times(s.P, b.col, b.H, W.middleCols(r, m->dim()));
      y.segment(r, m->dim()).noalias() -= b.H * dx.segment(b.col, b.H.cols());
    }
    r += m->dim();
  }
  // S = H (P H^T) + R + V V^T sigma^2: the shared gimbal noise correlates every pair of
  // projections of one camera (eq. 45); a block with such projections holds that camera's only.
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(rows, rows);
  r = 0;
  for (const auto* a : ms) {
    for (const auto& b : a->blocks) S.middleRows(r, a->dim()).noalias() += b.H * W.middleRows(b.col, b.H.cols());
    S.block(r, r, a->dim(), a->dim()) += a->R;
    if (a->camera >= 0) {
      int c = 0;
      for (const auto* b : ms) {
        S.block(r, c, a->dim(), b->dim()).noalias() +=
            a->orientation_sigma * a->orientation_sigma * a->V * b->V.transpose();
        c += b->dim();
      }
    }
    r += a->dim();
  }
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return false;
  // W = P H^T L^-T (S = L L^T), so K y = W L^-1 y and K S K^T = W W^T. The two O(n m^2) and
  // O(n^2 m) kernels are BLAS's (dtrsm, dsyrk); P and W are column-major with leading dimension n.
  const Eigen::MatrixXd& L = llt.matrixLLT();  // L in its lower triangle
  const int n = s.dim();
  cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, n, rows, 1.0, L.data(),
              static_cast<int>(L.outerStride()), W.data(), static_cast<int>(W.outerStride()));
  const Eigen::VectorXd v = llt.matrixL().solve(y);
  s.x.noalias() += W * v;  // eq. 43
  cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, n, rows, -1.0, W.data(),
              static_cast<int>(W.outerStride()), 1.0, s.P.data(), static_cast<int>(s.P.outerStride()));  // eq. 44
  return true;
}
}  // namespace

bool ekf_update(FilterState& s, const std::vector<const Measurement*>& ms) {
  if (ms.empty()) return true;
  const auto blocks = independent_blocks(ms);
  const int n = s.dim();
  const Eigen::VectorXd x0 = s.x;
  // The blocks write the lower triangle only: the upper one and this diagonal restore P on failure.
  const Eigen::VectorXd diagonal0 = s.P.diagonal();
  // Workspace kept between calls: a new n x rows matrix at every update costs page faults.
  static thread_local std::vector<double> workspace;
  for (const auto& b : blocks) {
    int rows = 0;
    for (const auto* m : b) rows += m->dim();
    if (workspace.size() < static_cast<std::size_t>(n) * rows) workspace.resize(static_cast<std::size_t>(n) * rows);
    if (block_update(s, b, x0, Eigen::Map<Eigen::MatrixXd>(workspace.data(), n, rows))) continue;
    s.x = x0;
    s.P.diagonal() = diagonal0;
    mirror_triangle(s.P, false);
    return false;
  }
  mirror_triangle(s.P, true);
  return true;
}

}  // namespace wingman::slam
