// Which cameras of a team share view, for cooperative initialisation (eq. 47-52) between every
// such pair rather than a fixed one: each camera's ground footprint as the filter estimates it.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <utility>
#include <vector>

#include "slam/estimator.hpp"

namespace wingman::app {

// Camera j's footprint on the horizontal plane at the lead's estimated height (the ground under a
// ground lead; nearer than the ground under an aerial one, so the footprint errs small): the
// bounding box of its image corners' rays from its estimated position through its commanded
// orientation. nullopt when a corner's ray does not meet the plane below the camera.
std::optional<Eigen::AlignedBox2d> ground_footprint(const slam::Estimator& est, int j);

// Pairs (a < b) of the cameras with sees[j] whose footprints overlap, largest overlap (as a
// fraction of the smaller footprint) first; a camera without a footprint pairs with every other.
std::vector<std::pair<int, int>> pairs_sharing_view(const slam::Estimator& est, const std::vector<bool>& sees);

}  // namespace wingman::app
