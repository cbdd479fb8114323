// A dataset as a ROS 1 bag (docs/ros_bag.md): every agent's ground truth on /tf and as odometry,
// the camera mounts on /tf_static, and per UAV its images, depth, camera_info, IMU, true camera
// pose and sensor samples, each message stamped with its sample's t_ns. Written through Debian's
// librosbag_storage; this header includes no ROS header, so callers stay C++20.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <string>

#include "datasets/dataset.hpp"

namespace wingman::datasets {

enum class BagCompression { None, Lz4, Bz2 };

struct BagExportOptions {
  BagCompression compression = BagCompression::None;
  // Called after each message with (written, total); it may throw to abandon the export (the
  // file is then incomplete, and the caller removes it).
  std::function<void(std::size_t, std::size_t)> progress;
};

struct BagExportSummary {
  std::map<std::string, std::size_t> messages;  // per topic
  std::size_t total() const;
};

// Topic and frame names (docs/ros_bag.md, topics).
std::string bag_body_frame(const std::string& agent);    // "<agent>/base_link"
std::string bag_camera_frame(const std::string& agent);  // "<agent>/cam0_optical"
inline constexpr const char* kBagWorldFrame = "world";

// Writes the bag at `path` (created or truncated; the caller stages it). Frames are loaded one at
// a time. Throws DatasetError for a frame that cannot be read, std::runtime_error for a bag that
// cannot be written, both naming the file.
BagExportSummary write_bag(const Dataset& ds, const std::filesystem::path& path,
                           const BagExportOptions& options = {});

}  // namespace wingman::datasets
