// The on-disk dataset of docs/datasets.md, what `wingman render` writes and a replay reads: one
// folder per agent in EuRoC's ASL layout (format version 2),
//   <agent>/mav0/cam0/data/<t_ns>.png, cam0/data.csv, cam0/sensor.yaml   8-bit grey (or RGB) frames
//   <agent>/mav0/depth0/...                                              16-bit depth, mm
//   <agent>/mav0/imu0/data.csv, sensor.yaml                              200 Hz IMU, noise model
//   <agent>/mav0/state_groundtruth_estimate0/data.csv                    EuRoC's 17 columns
//   <agent>/mav0/cam0_pose0/data.csv                                     true camera pose per frame
//   <agent>/mav0/{gps0,altimeter0,range0,ahrs0}/                         noisy sensor samples
// and a top-level dataset.yaml (format version, scenario, seed, software version). Format version
// 1 (no mav0/, groundtruth/) is still read (datasets/layout.hpp). The writer fills a directory
// the caller stages (app/cli/cmd_render.cpp renames it into place when complete); the reader
// validates what it loads and names the file at fault.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/layout.hpp"
#include "geometry/camera.hpp"
#include "geometry/lead_image.hpp"

namespace wingman::datasets {

inline constexpr int kFormatVersion = 2;  // the layout written; version 1 is still read
// Depth PNGs hold millimetres; 0 means no surface (sky) or farther than 65.535 m.
inline constexpr double kDepthScale = 0.001;

class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DatasetInfo {
  int format_version = kFormatVersion;
  std::string scenario;  // the scenario's name
  std::string variant;
  std::uint64_t seed = 0;
  std::string software_version;
  double rate = 10;  // Hz
  int frames = 0;    // per camera
  std::string renderer;  // which GL context made the frames
  std::vector<std::string> agents;
};

struct CameraInfo {
  geometry::PinholeCamera camera;
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();  // commanded (the filter's known input)
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();     // camera minus body position
  double rate = 10;
  int channels = 3;  // 3: RGB colour, 1: gray
  // The shutter (sim/camera_sensor.hpp), written to cam0/sensor.yaml with each row's time.
  bool rolling = false;
  double exposure_s = 0;
  double line_delay_s = 0;
  bool top_to_bottom = true;
  // A physical sensor's parameters (key, value), in cam0/sensor.yaml's `sensor:`; empty: ideal.
  std::vector<std::pair<std::string, double>> sensor;
  // Whether the frames carry an exposure time (cam0/exposure.csv is written).
  bool exposed() const { return exposure_s > 0 || !sensor.empty(); }
};

// cam0/exposure.csv: what a frame was taken with (the shutter's, or auto-exposure's, time and gain).
struct ExposureSample {
  std::int64_t t_ns = 0;
  double exposure_s = 0;
  double gain = 1;
};

// cam0_lead0/data.csv: where the lead is in a camera's frame, ground truth for lead detectors.
inline constexpr const char* kLeadLabelHeader =
    "#timestamp [ns],u [px],v [px],distance [m],visible [],box_u0 [px],box_v0 [px],box_u1 [px],box_v1 [px]";
struct LeadLabel {
  std::int64_t t_ns = 0;
  geometry::LeadImage lead;
};

// A body pose (state_groundtruth_estimate0: p_WB, q = R_WB, velocity in the world frame and the
// IMU's true biases) or a camera pose (cam0_pose0: p = camera centre in the world, q = R_CW, the
// world-to-camera rotation; v and the biases unused).
struct PoseSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector4d q_xyzw{0, 0, 0, 1};
  Eigen::Vector3d v = Eigen::Vector3d::Zero();    // body only
  Eigen::Vector3d b_w = Eigen::Vector3d::Zero();  // gyroscope bias, rad/s (body with an IMU)
  Eigen::Vector3d b_a = Eigen::Vector3d::Zero();  // accelerometer bias, m/s^2
};

// imu0/data.csv: angular rate and specific force in the IMU (= body) frame, biases and noise
// included, as EuRoC's w_RS_S and a_RS_S.
struct ImuSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d w_S = Eigen::Vector3d::Zero();  // rad/s
  Eigen::Vector3d a_S = Eigen::Vector3d::Zero();  // m/s^2
};

// imu0/sensor.yaml: the continuous-time noise model the samples were drawn with (Kalibr's and
// EuRoC's keys and units).
struct ImuInfo {
  double rate = 200;                          // Hz
  double gyroscope_noise_density = 0;         // rad/s/sqrt(Hz)
  double gyroscope_random_walk = 0;           // rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 0;     // m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 0;       // m/s^3/sqrt(Hz)
};

struct Vec3Sample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
};

struct ScalarSample {
  std::int64_t t_ns = 0;
  double value = 0;
};

struct AgentData {
  std::string name;
  std::optional<CameraInfo> camera;     // UAVs
  std::vector<std::int64_t> frames;     // cam0 and depth0 time stamps
  std::vector<PoseSample> groundtruth;  // body
  std::vector<PoseSample> camera_pose;  // true camera pose (with gimbal error), one per frame
  std::optional<ImuInfo> imu_info;      // UAVs (format version 2)
  std::vector<ImuSample> imu;
  std::vector<Vec3Sample> gps;
  std::vector<ScalarSample> altimeter, range, ahrs;
  std::vector<ExposureSample> exposure;  // cameras with an exposure time
  std::vector<LeadLabel> lead_labels;    // cameras of a scene with a lead model: one per frame
};

struct Dataset {
  std::filesystem::path root;
  DatasetInfo info;
  Layout layout;  // from info.format_version
  std::vector<AgentData> agents;

  const AgentData& agent(const std::string& name) const;  // throws DatasetError
  std::filesystem::path image_path(const std::string& agent, std::int64_t t_ns) const;
  std::filesystem::path depth_path(const std::string& agent, std::int64_t t_ns) const;
  // RGB (or gray) CV_8U image and depth in metres (CV_32F, 0 where unknown).
  cv::Mat load_image(const std::string& agent, std::int64_t t_ns) const;
  cv::Mat load_depth(const std::string& agent, std::int64_t t_ns) const;
};

// checksums.csv at the dataset's root: every frame's size and CRC-32 as `wingman render` wrote it,
// so that a replay verifies every frame before its first step without decoding one.
inline constexpr const char* kChecksumsFile = "checksums.csv";
struct FrameChecksum {
  std::uint64_t bytes = 0;
  std::uint32_t crc32 = 0;
};
std::uint32_t crc32_of(const unsigned char* data, std::size_t size);

// Time stamp of step k at a rate, in integer nanoseconds.
std::int64_t step_ns(int k, double rate);

// PNG encoding runs on background threads (it costs more than a GPU frame), at most a few frames
// queued per thread; an encoding error is rethrown by the next write_frame() or by finish().
class DatasetWriter {
 public:
  // `dir` must exist and be empty (the caller's staging directory). `threads` 0: one per core,
  // at most 8.
  DatasetWriter(std::filesystem::path dir, DatasetInfo info, unsigned threads = 0);
  ~DatasetWriter();
  DatasetWriter(const DatasetWriter&) = delete;
  DatasetWriter& operator=(const DatasetWriter&) = delete;
  // An agent, with a camera for a UAV. Creates its folders.
  void add_agent(const std::string& name, const std::optional<CameraInfo>& camera);
  // One frame: colour (RGB, CV_8UC3; written as gray when the camera has 1 channel) and depth in
  // metres (CV_32F).
  void write_frame(const std::string& agent, std::int64_t t_ns, const cv::Mat& rgb,
                   const cv::Mat& depth);
  void ground_truth(const std::string& agent, const PoseSample& s);
  void camera_pose(const std::string& agent, const PoseSample& s);
  void exposure(const std::string& agent, const ExposureSample& s);
  void lead_label(const std::string& agent, const LeadLabel& s);
  void gps(const std::string& agent, const Vec3Sample& s);
  void altimeter(const std::string& agent, const ScalarSample& s);
  void range(const std::string& agent, const ScalarSample& s);
  void ahrs(const std::string& agent, const ScalarSample& s);
  void imu_info(const std::string& agent, const ImuInfo& info);
  void imu(const std::string& agent, const ImuSample& s);
  // Waits for the images, then writes the CSVs, the sensor.yaml files and, last, dataset.yaml.
  void finish();

 private:
  struct Encoder;
  AgentData& get(const std::string& agent);
  std::filesystem::path dir_;
  Layout layout_;
  DatasetInfo info_;
  std::vector<AgentData> agents_;
  std::mutex checksums_mutex_;
  std::map<std::string, FrameChecksum> checksums_;  // path relative to the dataset's root
  std::unique_ptr<Encoder> encoder_;
};

// Loads and validates a dataset directory: dataset.yaml with a known format version, every
// agent's CSVs (finite values in range, increasing time stamps), every sensor.yaml (positive
// intrinsics, a rotation matrix, a positive rate), every listed frame present with the size
// sensor.yaml gives (read from the PNG header, so this is fast). Throws DatasetError naming the file.
Dataset read_dataset(const std::filesystem::path& dir);
// Every frame's bytes against checksums.csv (size and CRC-32), or, for a dataset without one,
// every frame decoded. Throws DatasetError naming the first bad frame. `progress(done, total)`.
void verify_frames(const Dataset& ds, const std::function<void(int, int)>& progress = {});

}  // namespace wingman::datasets
