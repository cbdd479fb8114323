#include "slam/motion_model.hpp"

#include <cmath>
#include <utility>
#include <vector>

namespace wingman::slam {

namespace {
// (position, velocity) column of every agent: the lead, then each camera.
std::vector<std::pair<int, int>> agent_blocks(const FilterState& s) {
  std::vector<std::pair<int, int>> b = {{FilterState::lead_pos(), FilterState::lead_vel()}};
  for (int j = 0; j < s.num_cameras(); ++j) b.emplace_back(FilterState::cam_pos(j), FilterState::cam_vel(j));
  return b;
}
}  // namespace

void predict_constant_velocity(FilterState& s, double dt, double sigma_a_lead, double sigma_a_uav,
                               double sigma_a_common) {
  const auto agents = agent_blocks(s);
  for (const auto& [pos, vel] : agents) {
    const double sigma_a = pos == FilterState::lead_pos() ? sigma_a_lead : sigma_a_uav;
    s.x.segment<3>(pos) += dt * s.x.segment<3>(vel);  // eq. 41
    // A P A^T, eq. 42: rows then columns of the position block gain dt times the velocity's.
    s.P.middleRows(pos, 3) += dt * s.P.middleRows(vel, 3);
    s.P.middleCols(pos, 3) += dt * s.P.middleCols(vel, 3);
    // W Q W^T: white acceleration integrated over dt enters the velocity.
    s.P.block<3, 3>(vel, vel).diagonal().array() += (sigma_a * dt) * (sigma_a * dt);
  }
  if (sigma_a_common > 0) {
    const double q = (sigma_a_common * dt) * (sigma_a_common * dt);
    for (const auto& a : agents)
      for (const auto& b : agents) s.P.block<3, 3>(a.second, b.second).diagonal().array() += q;
  }
}

void predict_common_acceleration(FilterState& s, double dt, double sigma, double tau) {
  const int a = s.common_acceleration();
  if (a < 0) return;
  const double phi = std::exp(-dt / tau);
  const Eigen::Vector3d acc = s.x.segment<3>(a);
  const auto agents = agent_blocks(s);
  // F = I + E_pa dt^2/2 + E_va dt + E_aa (phi - 1), on rows then columns; a's rows and columns
  // change last, so the others use its old values.
  for (const auto& [pos, vel] : agents) {
    s.x.segment<3>(pos) += 0.5 * dt * dt * acc;
    s.x.segment<3>(vel) += dt * acc;
    s.P.middleRows(pos, 3) += 0.5 * dt * dt * s.P.middleRows(a, 3);
    s.P.middleRows(vel, 3) += dt * s.P.middleRows(a, 3);
  }
  s.x.segment<3>(a) *= phi;
  s.P.middleRows(a, 3) *= phi;
  for (const auto& [pos, vel] : agents) {
    s.P.middleCols(pos, 3) += 0.5 * dt * dt * s.P.middleCols(a, 3);
    s.P.middleCols(vel, 3) += dt * s.P.middleCols(a, 3);
  }
  s.P.middleCols(a, 3) *= phi;
  s.P.block<3, 3>(a, a).diagonal().array() += (1 - phi * phi) * sigma * sigma;
}

void predict_gimbal_error(FilterState& s, int j, double dt, double sigma, double tau) {
  const int g = s.gimbal(j);
  if (g < 0) return;
  const double phi = std::exp(-dt / tau);
  s.x.segment<2>(g) *= phi;
  s.P.middleRows(g, 2) *= phi;
  s.P.middleCols(g, 2) *= phi;
  s.P.block<2, 2>(g, g).diagonal().array() += (1 - phi * phi) * sigma * sigma;
}

}  // namespace wingman::slam
