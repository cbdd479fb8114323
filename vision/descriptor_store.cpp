// Landmark descriptor store (see descriptor_store.hpp).
#include "vision/descriptor_store.hpp"

#include <algorithm>
#include <stdexcept>

namespace wingman::vision {

namespace {
cv::Mat one_row(const cv::Mat& d) {
  if (d.rows != 1) throw std::invalid_argument("DescriptorStore: expected one descriptor row, got " +
                                               std::to_string(d.rows));
  return d.clone();
}
}  // namespace

void DescriptorStore::add(LandmarkId id, const cv::Mat& descriptor, std::int64_t frame) {
  Entry e;
  e.initial = one_row(descriptor);
  e.created_frame = e.last_seen_frame = frame;
  entries_[id] = std::move(e);
}

void DescriptorStore::observe(LandmarkId id, const cv::Mat& descriptor, std::int64_t frame) {
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  it->second.latest = one_row(descriptor);
  it->second.last_seen_frame = std::max(it->second.last_seen_frame, frame);
  ++it->second.observations;
}

void DescriptorStore::remove(LandmarkId id) { entries_.erase(id); }

void DescriptorStore::remove(const std::vector<LandmarkId>& ids) {
  for (auto id : ids) entries_.erase(id);
}

std::vector<LandmarkId> DescriptorStore::prune(std::int64_t frame, std::int64_t max_age) {
  std::vector<LandmarkId> gone;
  for (const auto& [id, e] : entries_)
    if (frame - e.last_seen_frame > max_age) gone.push_back(id);
  std::sort(gone.begin(), gone.end());
  remove(gone);
  return gone;
}

const DescriptorStore::Entry* DescriptorStore::find(LandmarkId id) const {
  auto it = entries_.find(id);
  return it == entries_.end() ? nullptr : &it->second;
}

double DescriptorStore::distance(LandmarkId id, const cv::Mat& descriptor, int norm,
                                 bool with_latest) const {
  const Entry* e = find(id);
  if (!e) return -1.0;
  double d = cv::norm(e->initial, descriptor, norm);
  if (with_latest && !e->latest.empty()) d = std::min(d, cv::norm(e->latest, descriptor, norm));
  return d;
}

}  // namespace wingman::vision
