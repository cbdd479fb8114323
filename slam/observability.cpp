#include "slam/observability.hpp"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>

#include "geometry/rotation.hpp"

namespace wingman::slam {

namespace {

// Concatenation built piecewise: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
template <class... Parts>
std::string cat(const Parts&... parts) {
  std::string s;
  ((s += parts), ...);
  return s;
}

constexpr double kPixelSigma = 1.0;  // R is irrelevant to O; the builders want a value

// One fed measurement: its name, and its dense Jacobian at a state built by the filter's builder.
struct Feed {
  std::string name;
  int dim = 0;
  std::function<Measurement(const FilterState&)> build;
  // Pair whose relative motion sets the measurement's time scale: positions of two state blocks
  // (-1: none) and, for projections, the camera's R_CW row giving depth.
  int a = -1, b = -1;
  const CameraRig* depth_rig = nullptr;
};

Measurement require(std::optional<Measurement> m, const std::string& name) {
  if (!m) throw std::invalid_argument(cat("observability: ", name, " is behind its camera"));
  return *m;
}

std::vector<Feed> feeds_of(const EvaluationPoint& p, const SensorSet& s) {
  const FilterState& st = p.state;
  const int n2 = st.num_cameras();
  const int n1 = static_cast<int>(st.landmarks().size());
  if (s.num_uavs() != n2 || static_cast<int>(s.altimeter.size()) != n2 ||
      static_cast<int>(s.range.size()) != n2 || static_cast<int>(s.visibility.size()) != n2 ||
      static_cast<int>(p.rigs.size()) != n2)
    throw std::invalid_argument("observability: sensor set, rigs and state disagree on the UAV count");
  std::vector<Feed> feeds;
  const Eigen::Vector2d z2 = Eigen::Vector2d::Zero();
  for (int j = 0; j < n2; ++j) {
    const CameraRig* rig = &p.rigs[static_cast<std::size_t>(j)];
    const std::string uav = cat("uav", std::to_string(j + 1));
    for (int i : s.visibility[static_cast<std::size_t>(j)]) {
      if (i < 0 || i >= n1)
        throw std::invalid_argument(cat("observability: ", uav, " sees landmark ", std::to_string(i),
                                        ", but there are ", std::to_string(n1)));
      const LandmarkSlot lm = st.landmarks()[static_cast<std::size_t>(i)];
      const std::string name = cat("proj(", uav, ",lm", std::to_string(i), ")");
      feeds.push_back({name, 2,
                       [=](const FilterState& x) {
                         return require(landmark_measurement(x, lm, j, *rig, z2, kPixelSigma), name);
                       },
                       lm.offset, FilterState::cam_pos(j), rig});
    }
    if (s.sees_lead[static_cast<std::size_t>(j)]) {
      const std::string name = cat("proj(", uav, ",lead)");
      feeds.push_back({name, 2,
                       [=](const FilterState& x) {
                         return require(lead_projection_measurement(x, j, *rig, z2, kPixelSigma), name);
                       },
                       FilterState::lead_pos(), FilterState::cam_pos(j), rig});
    }
    if (s.altimeter[static_cast<std::size_t>(j)])
      feeds.push_back({cat("alt(", uav, ")"), 1,
                       [=](const FilterState& x) { return altimeter_measurement(x, j, *rig, 0, 1); }});
    if (s.range[static_cast<std::size_t>(j)])
      feeds.push_back({cat("range(", uav, ",lead)"), 1,
                       [=](const FilterState& x) { return range_measurement(x, j, *rig, 0, 1); },
                       FilterState::lead_pos(), FilterState::cam_pos(j)});
  }
  if (s.gps)
    feeds.push_back({"gps(lead)", 3, [](const FilterState& x) {
                       return gps_measurement(x, Eigen::Vector3d::Zero(), 1);
                     }});
  return feeds;
}

// Stacked dense Jacobian of every feed at state x.
Eigen::MatrixXd stacked_jacobian(const std::vector<Feed>& feeds, FilterState& s, int rows) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, s.dim());
  int r = 0;
  for (const Feed& f : feeds) {
    const Measurement m = f.build(s);
    for (const JacobianBlock& b : m.blocks) J.block(r, b.col, b.H.rows(), b.H.cols()) += b.H;
    r += f.dim;
  }
  return J;
}

// F = df/dx of the constant-velocity field (eq. 1): d(position)/dt = velocity for every agent.
Eigen::MatrixXd drift_jacobian(const FilterState& s) {
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(s.dim(), s.dim());
  for (int a = 0; a <= s.num_cameras(); ++a) {
    const int pos = a == 0 ? FilterState::lead_pos() : FilterState::cam_pos(a - 1);
    F.block(pos, pos + 3, 3, 3).setIdentity();
  }
  return F;
}

// Weights w[k][i] with sum_i w[k][i] g(i h) ~ h^k g^(k)(0) on nodes i = -m..m (exact for
// polynomials of degree 2m): the inverse of the scaled Vandermonde system.
Eigen::MatrixXd stencil_weights(int m) {
  const int n = 2 * m + 1;
  Eigen::MatrixXd V(n, n);  // V(p, i) = node_i^p / p!
  for (int i = 0; i < n; ++i) {
    double term = 1;
    for (int p = 0; p < n; ++p) {
      V(p, i) = term;
      term *= static_cast<double>(i - m) / (p + 1);
    }
  }
  // Row k of W solves V w = e_k: the weights reproduce the k-th Taylor coefficient.
  return V.fullPivLu().solve(Eigen::MatrixXd::Identity(n, n)).transpose();
}

// Shortest time over which a fed pair's relative geometry changes appreciably: the distance of
// the nearest complex singularity of t -> H(Phi(t, x)) (depth or range reaching zero) is at
// least depth / relative speed. Stencils span a fraction of it.
double time_scale(const std::vector<Feed>& feeds, const FilterState& s) {
  double T = std::numeric_limits<double>::infinity();
  for (const Feed& f : feeds) {
    if (f.a < 0) continue;
    const Eigen::Vector3d d = s.x.segment<3>(f.a) - s.x.segment<3>(f.b);
    const auto vel = [&](int pos) -> Eigen::Vector3d {
      // Landmarks are static; agents' velocities follow their positions.
      return pos < s.agent_dim() ? Eigen::Vector3d(s.x.segment<3>(pos + 3)) : Eigen::Vector3d::Zero();
    };
    const Eigen::Vector3d w = vel(f.a) - vel(f.b);
    const double dist = f.depth_rig ? (f.depth_rig->R_CW * d).z() : d.norm();
    if (w.norm() > 0) T = std::min(T, dist / w.norm());
  }
  return std::isfinite(T) ? T : 1.0;  // nothing moves relative to anything: H is constant
}

// Gradients of L^0..L^order of every feed, stacked by order: H^(k)(0) + k H^(k-1)(0) F.
Eigen::MatrixXd lie_gradients(const std::vector<Feed>& feeds, const FilterState& s0, int order,
                              int rows, double dt, int m) {
  const Eigen::MatrixXd W = stencil_weights(m);
  const Eigen::MatrixXd F = drift_jacobian(s0);
  const Eigen::VectorXd f = F * s0.x;
  FilterState s = s0;
  std::vector<Eigen::MatrixXd> Jt;  // H along the flow at t = i dt
  for (int i = -m; i <= m; ++i) {
    s.x = s0.x + (i * dt) * f;  // the exact constant-velocity flow
    Jt.push_back(stacked_jacobian(feeds, s, rows));
  }
  Eigen::MatrixXd G(rows * (order + 1), s0.dim());
  Eigen::MatrixXd prev;  // H^(k-1)(0)
  for (int k = 0; k <= order; ++k) {
    Eigen::MatrixXd Dk = Jt[static_cast<std::size_t>(m)];  // H^(0)(0) exactly
    if (k > 0) {
      Dk.setZero();
      for (int i = 0; i < 2 * m + 1; ++i) Dk += W(k, i) * Jt[static_cast<std::size_t>(i)];
      Dk /= std::pow(dt, k);
    }
    G.middleRows(k * rows, rows) = k > 0 ? Eigen::MatrixXd(Dk + k * prev * F) : Dk;
    prev = std::move(Dk);
  }
  return G;
}

// Row scale making rows of different measurements and orders comparable: T^k / |H_i(0)| for
// measurement i at order k (scaling rows changes neither the rank nor the null space, and rows
// that are zero in exact arithmetic stay at rounding level).
Eigen::VectorXd row_scale(const std::vector<Feed>& feeds, const Eigen::MatrixXd& G, int order,
                          int rows, double T) {
  Eigen::VectorXd scale(rows * (order + 1));
  int r = 0;
  for (const Feed& fd : feeds) {
    const double n0 = G.middleRows(r, fd.dim).norm();
    for (int k = 0; k <= order; ++k)
      scale.segment(k * rows + r, fd.dim).setConstant(std::pow(T, k) / (n0 > 0 ? n0 : 1.0));
    r += fd.dim;
  }
  return scale;
}

}  // namespace

SensorSet SensorSet::empty(int num_uavs, int num_landmarks, bool all_landmarks) {
  SensorSet s;
  const auto n = static_cast<std::size_t>(num_uavs);
  s.sees_lead.assign(n, false);
  s.altimeter.assign(n, false);
  s.range.assign(n, false);
  s.visibility.assign(n, {});
  if (all_landmarks)
    for (auto& v : s.visibility)
      for (int i = 0; i < num_landmarks; ++i) v.push_back(i);
  return s;
}

FilterState make_filter_state(const Eigen::Vector3d& lead_pos, const Eigen::Vector3d& lead_vel,
                              const std::vector<Eigen::Vector3d>& cam_pos,
                              const std::vector<Eigen::Vector3d>& cam_vel,
                              const std::vector<Eigen::Vector3d>& landmarks) {
  if (cam_pos.size() != cam_vel.size())
    throw std::invalid_argument("make_filter_state: positions and velocities differ in count");
  FilterState s(static_cast<int>(cam_pos.size()));
  s.x.segment<3>(FilterState::lead_pos()) = lead_pos;
  s.x.segment<3>(FilterState::lead_vel()) = lead_vel;
  for (std::size_t j = 0; j < cam_pos.size(); ++j) {
    s.x.segment<3>(FilterState::cam_pos(static_cast<int>(j))) = cam_pos[j];
    s.x.segment<3>(FilterState::cam_vel(static_cast<int>(j))) = cam_vel[j];
  }
  for (const auto& a : landmarks)
    s.add_landmark(LandmarkKind::Euclidean, a, Eigen::MatrixXd::Zero(3, s.dim()),
                   Eigen::Matrix3d::Identity());
  return s;
}

EvaluationPoint generic_point(int num_uavs, int num_landmarks, unsigned long seed) {
  if (num_uavs < 1 || num_landmarks < 0)
    throw std::invalid_argument("generic_point: at least one UAV and no negative landmark count");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto vec = [&](double sx, double sy, double sz, double oz) {
    return Eigen::Vector3d(sx * u(rng), sy * u(rng), oz + sz * u(rng));
  };
  const Eigen::Vector3d lead_pos = vec(5, 5, 1, 0), lead_vel = vec(1, 1, 1, 0);
  std::vector<Eigen::Vector3d> cp, cv, lm;
  for (int j = 0; j < num_uavs; ++j) {
    cp.push_back(vec(5, 5, 3, 15));
    cv.push_back(vec(1, 1, 1, 0));
  }
  for (int i = 0; i < num_landmarks; ++i) lm.push_back(vec(10, 10, 1, 0));
  EvaluationPoint p;
  p.state = make_filter_state(lead_pos, lead_vel, cp, cv, lm);
  CameraRig rig;  // the paper's camera, nadir (docs/design.md, frames and conventions)
  rig.model = geometry::PinholeCamera(200.1, 200.1, 500, 500, 1000, 1000);
  rig.R_CW = geometry::nadir_R_CW();
  p.rigs.assign(static_cast<std::size_t>(num_uavs), rig);
  return p;
}

std::vector<std::string> state_names(const FilterState& s) {
  std::vector<std::string> names;
  const auto agent = [&](const std::string& who) {
    for (const char* c : {"x", "y", "z", "vx", "vy", "vz"}) names.push_back(cat(who, ".", c));
  };
  agent("lead");
  for (int j = 0; j < s.num_cameras(); ++j) agent(cat("uav", std::to_string(j + 1)));
  for (std::size_t i = 0; i < s.landmarks().size(); ++i) {
    const LandmarkSlot& lm = s.landmarks()[i];
    if (lm.kind == LandmarkKind::Euclidean) {
      for (const char* c : {"x", "y", "z"}) names.push_back(cat("lm", std::to_string(i), ".", c));
    } else {
      for (const char* c : {"x0", "y0", "z0", "theta", "phi", "rho"})
        names.push_back(cat("lm", std::to_string(i), ".", c));
    }
  }
  return names;
}

ObservabilityMatrix observability_matrix(const EvaluationPoint& p, const SensorSet& sensors,
                                         int order) {
  if (order < 0 || order > kMaxLieOrder)
    throw std::invalid_argument(cat("observability: Lie order ", std::to_string(order), " outside 0..",
                                    std::to_string(kMaxLieOrder)));
  const std::vector<Feed> feeds = feeds_of(p, sensors);
  int rows = 0;
  for (const Feed& f : feeds) rows += f.dim;
  ObservabilityMatrix out;
  for (int k = 0; k <= order; ++k)
    for (const Feed& f : feeds)
      for (int c = 0; c < f.dim; ++c)
        out.rows.push_back(cat("L", std::to_string(k), " ", f.name,
                               f.dim == 1 ? std::string() : std::string(1, '.') + "uvxyz"[c + (f.dim == 3 ? 2 : 0)]));
  if (rows == 0) {
    out.O = Eigen::MatrixXd::Zero(0, p.state.dim());
    return out;
  }
  // 13-point stencils spanning +-T/8: truncation ~ (1/8)^(13-k), rounding ~ eps 48^k; a second
  // evaluation with another step estimates what is left of either.
  const int m = 6;
  const double T = time_scale(feeds, p.state);
  const double dt = T / (8.0 * m);
  const Eigen::MatrixXd G = lie_gradients(feeds, p.state, order, rows, dt, m);
  out.row_scale = row_scale(feeds, G, order, rows, T);
  out.O = out.row_scale.asDiagonal() * G;
  if (order > 0) {
    const Eigen::MatrixXd O2 = out.row_scale.asDiagonal() * lie_gradients(feeds, p.state, order, rows, 0.7 * dt, m);
    const double scale = out.O.cwiseAbs().maxCoeff();
    out.derivative_error = scale > 0 ? (out.O - O2).cwiseAbs().maxCoeff() / scale : 0;
  }
  return out;
}

ObservabilityReport analyse(const ObservabilityMatrix& m, const std::vector<std::string>& names,
                            double tolerance, double state_tolerance) {
  ObservabilityReport r;
  r.dim = static_cast<int>(m.O.cols());
  if (static_cast<int>(names.size()) != r.dim)
    throw std::invalid_argument("observability: one name per state column");
  r.names = names;
  r.tolerance = tolerance;
  r.state_tolerance = state_tolerance;
  Eigen::MatrixXd V;
  if (m.O.rows() > 0) {
    Eigen::BDCSVD<Eigen::MatrixXd> svd(m.O, Eigen::ComputeFullV);
    r.singular_values = svd.singularValues();
    V = svd.matrixV();
    const double smax = r.singular_values.size() ? r.singular_values(0) : 0.0;
    for (Eigen::Index i = 0; i < r.singular_values.size(); ++i)
      if (r.singular_values(i) > tolerance * smax) ++r.rank;
  } else {
    V = Eigen::MatrixXd::Identity(r.dim, r.dim);
  }
  r.null_space = V.rightCols(r.dim - r.rank);
  // A sign convention that makes printed bases reproducible: largest entry of each column positive.
  for (Eigen::Index c = 0; c < r.null_space.cols(); ++c) {
    Eigen::Index imax = 0;
    r.null_space.col(c).cwiseAbs().maxCoeff(&imax);
    if (r.null_space(imax, c) < 0) r.null_space.col(c) *= -1;
  }
  r.observable.resize(static_cast<std::size_t>(r.dim));
  for (int i = 0; i < r.dim; ++i)
    r.observable[static_cast<std::size_t>(i)] = r.null_space.row(i).norm() <= state_tolerance;
  return r;
}

Eigen::MatrixXd readable_basis(const Eigen::MatrixXd& N, std::vector<int>* pivots) {
  if (pivots) pivots->clear();
  // Reduced row echelon form of N^T, pivots taken in state order (partial pivoting within a
  // column); entries of an orthonormal N are <= 1, so 1e-6 separates zero from not.
  Eigen::MatrixXd A = N.transpose();
  Eigen::Index lead = 0;
  for (Eigen::Index c = 0; c < A.cols() && lead < A.rows(); ++c) {
    Eigen::Index best = 0;
    if (A.col(c).tail(A.rows() - lead).cwiseAbs().maxCoeff(&best) < 1e-6) continue;
    A.row(lead).swap(A.row(lead + best));
    A.row(lead) /= A(lead, c);
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      if (i != lead) A.row(i) -= A(i, c) * A.row(lead);
    if (pivots) pivots->push_back(static_cast<int>(c));
    ++lead;
  }
  Eigen::MatrixXd B = A.transpose();
  B = (B.array().abs() < 1e-8).select(0.0, B);  // rounding noise of the SVD prints as 0
  return B;
}

double subspace_angle(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  if (A.cols() != B.cols() || A.rows() != B.rows()) return M_PI / 2;
  if (A.cols() == 0) return 0;
  const auto orth = [](const Eigen::MatrixXd& X) {
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
    return Eigen::MatrixXd(qr.householderQ() * Eigen::MatrixXd::Identity(X.rows(), X.cols()));
  };
  const Eigen::VectorXd c = (orth(A).transpose() * orth(B)).jacobiSvd().singularValues();
  return std::acos(std::clamp(c.minCoeff(), -1.0, 1.0));
}

}  // namespace wingman::slam
