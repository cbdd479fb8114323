// Descriptors of the map's landmarks, keyed by landmark id. Each landmark keeps the descriptor it
// was initialised with (an anchor that cannot drift) and the latest one the estimator accepted
// (follows slow appearance changes, but also lets a track slide along an object's silhouette, so
// tracking uses it only when asked: TrackingSettings::match_latest_descriptor).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <unordered_map>
#include <vector>

#include "geometry/pose.hpp"

namespace wingman::vision {

using LandmarkId = geometry::LandmarkId;

class DescriptorStore {
 public:
  struct Entry {
    cv::Mat initial, latest;  // one row each; latest is empty until a match is accepted
    std::int64_t created_frame = 0, last_seen_frame = 0;
    int observations = 0;     // accepted matches after initialisation
  };

  // A new landmark with the descriptor of the feature it was initialised from (copied).
  // Replaces an existing entry with the same id.
  void add(LandmarkId id, const cv::Mat& descriptor, std::int64_t frame);
  // The estimator accepted a match of `id` to a feature with this descriptor. Unknown ids are
  // ignored (the landmark may have been dropped meanwhile).
  void observe(LandmarkId id, const cv::Mat& descriptor, std::int64_t frame);
  void remove(LandmarkId id);
  void remove(const std::vector<LandmarkId>& ids);
  // Drops entries not seen (initialised or accepted) for more than max_age frames, e.g. ids the
  // estimator dropped without telling; returns them.
  std::vector<LandmarkId> prune(std::int64_t frame, std::int64_t max_age);

  const Entry* find(LandmarkId id) const;
  bool contains(LandmarkId id) const { return entries_.count(id) > 0; }
  std::size_t size() const { return entries_.size(); }
  // Distance from `descriptor` to the landmark's initial descriptor, or the smaller of that and
  // the distance to its latest one when with_latest (norm as in Features::norm); a negative value
  // when the id is unknown.
  double distance(LandmarkId id, const cv::Mat& descriptor, int norm, bool with_latest = false) const;

 private:
  std::unordered_map<LandmarkId, Entry> entries_;
};

}  // namespace wingman::vision
