#include "sim/closed_loop_truth.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/rng.hpp"

namespace wingman::sim {

ClosedLoopTruth::ClosedLoopTruth(const Scenario& scn) : Truth(scn), lead_(scn) {
  if (!scn.closed_loop()) throw std::invalid_argument("ClosedLoopTruth needs a control: section");
  for (const UavSpec& u : scn.uavs) {
    KinematicState k;
    k.position = u.initial_position;
    uavs_.push_back(k);
    double yaw = 0;
    for (const UavControlSpec& c : scn.control.uavs)
      if (c.uav == u.name) yaw = c.initial_yaw;
    yaw_.push_back(yaw);
  }
}

void ClosedLoopTruth::check_time(double t) const {
  if (std::abs(t - t_) > 1e-9)
    throw std::logic_error("ClosedLoopTruth: asked for t = " + std::to_string(t) +
                           " while the state is at t = " + std::to_string(t_));
}

KinematicState ClosedLoopTruth::lead(double t) const { return lead_.lead(t); }

KinematicState ClosedLoopTruth::uav(int j, double t) const {
  check_time(t);
  return uavs_.at(static_cast<std::size_t>(j));
}

double ClosedLoopTruth::uav_yaw(int j, double t) const {
  check_time(t);
  return yaw_.at(static_cast<std::size_t>(j));
}

void ClosedLoopTruth::set_uav(int j, const Eigen::Vector3d& position,
                              const Eigen::Vector3d& velocity, double yaw) {
  auto& k = uavs_.at(static_cast<std::size_t>(j));
  k.position = position;
  k.velocity = velocity;
  yaw_[static_cast<std::size_t>(j)] = yaw;
}

Eigen::Vector4d ClosedLoopTruth::horizontal_extent() const {
  Eigen::Vector4d box(INFINITY, INFINITY, -INFINITY, -INFINITY);
  for (int k = 0; k <= scn_.num_steps(); ++k) {
    const Eigen::Vector3d p = lead_.lead(k * scn_.dt()).position;
    box.head<2>() = box.head<2>().cwiseMin(p.head<2>());
    box.tail<2>() = box.tail<2>().cwiseMax(p.head<2>());
  }
  double r = 0;
  for (const UavSpec& u : scn_.uavs)
    r = std::max(r, (u.initial_position - scn_.lead.initial_position).head<2>().norm());
  for (const UavControlSpec& c : scn_.control.uavs) r = std::max(r, c.lambda_d.head<2>().norm());
  r += 10.0;
  return box + Eigen::Vector4d(-r, -r, r, r);
}

InputDisturbance::InputDisturbance(const Eigen::Vector4d& bound, int num_uavs, std::uint64_t seed)
    : bound_(bound) {
  auto rng = make_stream(seed, "input_disturbance");
  std::uniform_real_distribution<double> freq(0.05, 0.5), phase(0.0, 2 * M_PI);
  for (int j = 0; j < num_uavs; ++j) {
    Eigen::Matrix<double, 4, 4> p;
    for (int i = 0; i < 4; ++i) p.col(i) << freq(rng), phase(rng), freq(rng), phase(rng);
    params_.push_back(p);
  }
}

Eigen::Vector4d InputDisturbance::operator()(int j, double t) const {
  const auto& p = params_.at(static_cast<std::size_t>(j));
  Eigen::Vector4d d;
  for (int i = 0; i < 4; ++i)
    d(i) = bound_(i) * (0.6 * std::sin(p(0, i) * t + p(1, i)) + 0.4 * std::sin(p(2, i) * t + p(3, i)));
  return d;
}

}  // namespace wingman::sim
