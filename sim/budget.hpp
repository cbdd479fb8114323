// What a run will cost, estimated from the scenario alone before anything is built, and the
// bounds a scenario must stay inside. Every size-driving key (duration and rate drive the steps,
// the landmark density and margin the synthetic field, the terrain's extent and resolution the
// mesh, the cameras' resolution the pixels, the UAV list the agents) is checked against what it
// drives, and the whole run's memory against the machine's; a run refused here names the key
// and the estimate, where a run let through would end in std::bad_alloc hours later.
#pragma once

#include <cstdint>
#include <string>

#include "sim/limits.hpp"
#include "sim/scenario.hpp"

namespace wingman::sim {

struct RunEstimate {
  double steps = 0;             // after t = 0
  double extent_m = 0;          // side of the flight's horizontal bounding box
  double max_abs_z_m = 0;       // the flight's largest height (or depth) from z = 0
  double landmarks = 0;         // synthetic field points
  double terrain_vertices = 0;  // rendered: terrain mesh vertices
  double pixels = 0;            // rendered: pixels of one step's frames, every camera
  double bytes = 0;             // peak memory, all of the above plus per-step records
  double seconds = 0;           // wall time on a 2-core machine, order of magnitude
};


RunEstimate estimate_run(const Scenario& s);
// The memory a run may use on this machine, bytes.
double memory_available();
// "1.5 GiB", "3.2 h": numbers in messages.
std::string bytes_text(double bytes);
std::string duration_text(double seconds);

}  // namespace wingman::sim
