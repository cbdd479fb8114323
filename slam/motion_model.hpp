// Constant-velocity prediction (paper eq. 33-34, 41-42) of the lead and every camera; landmarks
// are static. A = [I dt I; 0 I] per agent is applied as row and column operations on P, so the
// prediction costs O(n) per agent instead of a dense A P A^T.
#pragma once

#include "slam/state.hpp"

namespace wingman::slam {

// sigma_a_*: std of the white acceleration (m/s^2); the velocity takes noise a dt (eq. 34).
// sigma_a_common: an acceleration every agent shares. Agents in formation accelerate together; with
// independent noise only, a common acceleration that landmarks reveal for the UAVs is not passed
// on to the lead, whose velocity then lags and is overconfident (docs/results.md). The velocity
// blocks of agents i and k take (sigma_common^2 + [i = k] sigma_i^2) dt^2 I.
void predict_constant_velocity(FilterState& s, double dt, double sigma_a_lead, double sigma_a_uav,
                               double sigma_a_common = 0);

// The shared acceleration a, when the state holds it (FilterState::common_acceleration): every
// agent's position gains dt^2/2 a and its velocity dt a; a itself is a first-order Gauss-Markov
// process (Singer) with stationary std `sigma` (m/s^2) and correlation time `tau` (s). The
// formation's manoeuvre is smooth and slow, which white acceleration noise describes badly: to
// follow it, white noise must be large, and the velocities come out conservative. Applied after
// predict_constant_velocity (the composition is the Singer transition). A no-op without the state.
void predict_common_acceleration(FilterState& s, double dt, double sigma, double tau);

// Camera j's gimbal error, when the state holds it, as a first-order Gauss-Markov process with
// stationary std `sigma` (rad) and correlation time `tau` (s): a <- exp(-dt/tau) a, with noise
// (1 - exp(-2 dt/tau)) sigma^2 so that its variance tends to sigma^2. A slowly varying pointing
// error is not white: treating it as white noise makes the filter believe every frame's
// landmarks anew and overconfident. A no-op without gimbal states.
void predict_gimbal_error(FilterState& s, int j, double dt, double sigma, double tau);

}  // namespace wingman::slam
