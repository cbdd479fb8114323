// Constant-velocity prediction (paper eq. 33-34, 41-42) of the lead and every camera; landmarks
// are static. A = [I dt I; 0 I] per agent is applied as row and column operations on P, so the
// prediction costs O(n) per agent instead of a dense A P A^T.
#pragma once

#include "slam/state.hpp"

namespace wingman::slam {

// sigma_a_*: std of the white acceleration (m/s^2); the velocity takes noise a dt (eq. 34).
void predict_constant_velocity(FilterState& s, double dt, double sigma_a_lead, double sigma_a_uav);

}  // namespace wingman::slam
