// Where each file of a dataset lives, for the layout each format version has (docs/datasets.md):
//   version 2: EuRoC/ASL exactly, <agent>/mav0/<sensor>/..., the ground truth in
//              state_groundtruth_estimate0 (17 columns), the true camera poses in cam0_pose0;
//   version 1: <agent>/<sensor>/..., the ground truth in groundtruth/data.csv (11 columns) and
//              the camera poses in groundtruth/cam0.csv; read, no longer written.
#pragma once

#include <filesystem>
#include <string>

namespace wingman::datasets {

inline constexpr const char* kImuHeader =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]";
inline constexpr const char* kGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
    "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
    "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
    "b_a_RS_S_z [m s^-2]";
inline constexpr const char* kCameraPoseHeader =
    "#timestamp [ns],p_WC_W_x [m],p_WC_W_y [m],p_WC_W_z [m],q_WC_w [],q_WC_x [],q_WC_y [],q_WC_z []";
inline constexpr const char* kFramesHeader = "#timestamp [ns],filename";

struct Layout {
  int version = 2;

  std::filesystem::path agent(const std::filesystem::path& root, const std::string& name) const {
    return version >= 2 ? root / name / "mav0" : root / name;
  }
  std::filesystem::path sensor(const std::filesystem::path& root, const std::string& name,
                               const std::string& sensor) const {
    return agent(root, name) / sensor;
  }
  std::filesystem::path groundtruth_csv(const std::filesystem::path& root, const std::string& name) const {
    return version >= 2 ? sensor(root, name, "state_groundtruth_estimate0") / "data.csv"
                        : sensor(root, name, "groundtruth") / "data.csv";
  }
  std::filesystem::path camera_pose_csv(const std::filesystem::path& root, const std::string& name) const {
    return version >= 2 ? sensor(root, name, "cam0_pose0") / "data.csv"
                        : sensor(root, name, "groundtruth") / "cam0.csv";
  }
  // A frame's path relative to the dataset's root, as checksums.csv lists it.
  std::string frame_relative(const std::string& name, bool depth, std::int64_t t_ns) const {
    return (std::filesystem::path(name) / (version >= 2 ? "mav0" : "") / (depth ? "depth0" : "cam0") / "data" /
            (std::to_string(t_ns) + ".png"))
        .lexically_normal()
        .generic_string();
  }
};

}  // namespace wingman::datasets
