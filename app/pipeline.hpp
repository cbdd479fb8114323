// The open-loop pipeline on synthetic measurements: truth -> synthetic source -> estimator, one
// step at a time, with the bookkeeping evaluation needs (truth of every landmark the filter
// initialises, outliers injected and accepted, per-stage timings). Only app/ wires sim and slam.
#pragma once

#include <functional>

#include "eval/run_record.hpp"
#include "sim/scenario.hpp"
#include "slam/state.hpp"

namespace wingman::app {

// Called after each step with (steps done, steps in total).
using ProgressFn = std::function<void(int, int)>;

// Called after each step with the filter state, for invariant checks (tests) and inspection.
using StateObserver = std::function<void(int, const slam::FilterState&)>;

eval::RunRecord run_synthetic(const sim::Scenario& scn, const ProgressFn& progress = {},
                              const StateObserver& observer = {});

}  // namespace wingman::app
