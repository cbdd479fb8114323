// The one home of the bounds on a run's size: what the scenario reader refuses before a run
// starts (sim/budget.hpp estimates a run against them; docs/reliability.md).
#pragma once

namespace wingman::sim {

// Limits, chosen well above any experiment the shipped scenes model (docs/reliability.md).
struct RunLimits {
  static constexpr double kMaxSteps = 5e6;             // 1000 Hz for 83 min, 10 Hz for 5.8 days
  static constexpr int kMaxUavs = 64;
  static constexpr double kMaxCoordinate = 1e5;        // m from the origin (100 km)
  static constexpr double kMaxLandmarks = 5e6;
  static constexpr double kMaxTerrainVertices = 2e7;
  static constexpr double kMaxPixelsPerStep = 2.5e8;   // e.g. 16 cameras of 4000 x 4000
  static constexpr double kMaxSeconds = 7 * 86400.0;   // a week of wall time
  // The memory a run may plan to use: this fraction of the machine's (or of RLIMIT_AS if lower).
  static constexpr double kMemoryFraction = 0.75;
};

}  // namespace wingman::sim
