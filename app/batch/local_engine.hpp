// `wingman montecarlo --engine local`: the seeds in worker processes on this machine, each a
// `wingman run` (app/batch/montecarlo_runs.hpp) logging into <out>/runs/seed<S>.log. Workers are
// processes, not threads, so a crash or an abort in one run costs that run only; a worker stops
// when its parent dies, even by SIGKILL (io/interrupt.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "app/batch/montecarlo_runs.hpp"

namespace wingman::app {

// Runs `pending` in `jobs` workers at a time, adding each seed to `seeds` as it ends. On
// SIGINT/SIGTERM stops the running workers (which remove their own staging directories) and
// returns EngineEnd::interrupted.
EngineEnd run_local(const RunSpec& spec, const std::filesystem::path& out,
                    const std::vector<std::uint64_t>& pending, int jobs, bool quiet, SeedOutcomes& seeds);

}  // namespace wingman::app
