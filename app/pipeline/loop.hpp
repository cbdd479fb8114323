// The estimator's loop over a run's steps: predict, measure, update, initialise, record. Every
// measurement comes through one MeasurementSource, so the loop is the same whether they are
// synthetic, rendered or replayed; a closed loop adds what LoopHooks say.
#pragma once

#include <functional>

#include "app/pipeline/measurements.hpp"
#include "app/config/run_config.hpp"
#include "eval/metrics/run_record.hpp"
#include "sim/truth.hpp"
#include "slam/estimator.hpp"

namespace wingman::app {

// Called after each step with (steps done, steps in total).
using ProgressFn = std::function<void(int, int)>;
// Called after each step with the filter state, for invariant checks (tests) and inspection.
using StateObserver = std::function<void(int, const slam::FilterState&)>;

// What a closed loop adds to the open-loop step: bring the truth to t before anything is
// measured, and compute the commands from the updated estimate (filling the step's record).
struct LoopHooks {
  std::function<void(int k, double t)> advance;
  std::function<void(int k, double t, const slam::Estimator&, eval::StepRecord&)> control;
};

eval::RunRecord run_loop(const RunConfig& cfg, const sim::Truth& truth, MeasurementSource& source,
                         const LoopHooks& hooks = {}, const ProgressFn& progress = {},
                         const StateObserver& observer = {});

}  // namespace wingman::app
