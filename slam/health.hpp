// The filter's numerical health, checked where it can break: a state or covariance entry that is
// no longer finite, a variance below zero, a covariance that is no longer symmetric positive
// semi-definite, a measurement whose innovation is not finite. An EKF that breaks this way keeps
// running and prints NaN, or worse a plausible number; these checks turn that into an error at the
// step and stage it happens, naming the state element and the measurements involved.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "slam/measurement_models.hpp"
#include "slam/state.hpp"

namespace wingman::slam {

struct NumericalFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Names state element i: "lead position z", "camera 2 velocity x", "landmark 17", ...
std::string describe_state_element(const FilterState& s, int i);

// O(n) plus O(n) per agent row, cheap enough after every stage: x finite; every variance finite
// and >= 0; and for the agents' rows every 2x2 principal minor >= 0 (|P_ij|^2 <= P_ii P_jj), a
// necessary condition of positive semi-definiteness. Throws NumericalFailure naming `stage`.
void check_state(const FilterState& s, const std::string& stage);
// O(n^2), once a step: every entry of P finite, P symmetric, and the agents' block (the NEES's)
// positive semi-definite by its LDL^T factorisation.
void check_covariance(const FilterState& s, const std::string& stage);
// A measurement whose observed or predicted value is not finite, named by `what`.
void check_measurement(const Measurement& m, const std::string& what);

}  // namespace wingman::slam
