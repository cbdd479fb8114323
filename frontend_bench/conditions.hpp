// The conditions of the matching benchmark (docs/frontend.md, conditions): the same scenario and
// seed rendered through another camera or under another light, so that every frame is taken from
// the reference dataset's true poses. As HPatches compares a reference image with the others, a
// pair's frame A is always the reference's and frame B its condition's.
#pragma once

#include <string>
#include <vector>

#include "datasets/dataset.hpp"

namespace wingman::frontend_bench {

// The name of the reference dataset's own frames, in pairs.csv and the scores.
inline constexpr const char* kReference = "reference";

struct Condition {
  std::string name;  // [A-Za-z0-9_-]+, not "reference"
  datasets::Dataset dataset;
};

// Whether `condition` images the reference's flight: the same agents with cameras, frame time
// stamps, image sizes and true camera poses (cam0_pose0 within kPoseTolerance). Throws
// datasets::DatasetError naming the condition's file (and line) and what differs.
inline constexpr double kPoseTolerance = 1e-9;  // m, and the quaternion's components
void check_condition(const datasets::Dataset& reference, const Condition& condition);

// The reference dataset (held by reference: it must outlive this) and its conditions.
class Conditions {
 public:
  // Throws std::invalid_argument for a bad or repeated name, datasets::DatasetError for a
  // condition that does not image the reference's flight (check_condition).
  explicit Conditions(const datasets::Dataset& reference, std::vector<Condition> conditions = {});
  const datasets::Dataset& reference() const { return *reference_; }
  const std::vector<Condition>& conditions() const { return conditions_; }
  // The dataset of "reference" or a condition; null for a name it does not know.
  const datasets::Dataset* find(const std::string& name) const;
  // "reference, low_sun, blur": for messages.
  std::string names() const;

 private:
  const datasets::Dataset* reference_;
  std::vector<Condition> conditions_;
};

}  // namespace wingman::frontend_bench
