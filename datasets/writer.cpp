#include <fmt/format.h>
#include <fmt/os.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <fstream>
#include <mutex>
#include <thread>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <zlib.h>

#include "datasets/dataset.hpp"

namespace fs = std::filesystem;

namespace wingman::datasets {

std::uint32_t crc32_of(const unsigned char* data, std::size_t size) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  while (size > 0) {  // zlib takes uInt lengths
    const uInt n = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
    crc = ::crc32(crc, data, n);
    data += n;
    size -= n;
  }
  return static_cast<std::uint32_t>(crc);
}

std::int64_t step_ns(int k, double rate) {
  return static_cast<std::int64_t>(std::llround(static_cast<double>(k) * 1e9 / rate));
}

// A bounded queue of encoding jobs served by worker threads.
struct DatasetWriter::Encoder {
  explicit Encoder(unsigned threads) : limit(4 * threads) {
    for (unsigned i = 0; i < threads; ++i) workers.emplace_back([this] { serve(); });
  }
  ~Encoder() {
    {
      std::lock_guard lock(m);
      stop = true;
    }
    cv_jobs.notify_all();
    for (auto& w : workers) w.join();
  }
  void push(std::function<void()> job) {
    std::unique_lock lock(m);
    cv_room.wait(lock, [&] { return jobs.size() < limit || error; });
    rethrow_locked();
    jobs.push_back(std::move(job));
    cv_jobs.notify_one();
  }
  // Waits until every queued job is done; rethrows the first error.
  void drain() {
    std::unique_lock lock(m);
    cv_room.wait(lock, [&] { return (jobs.empty() && busy == 0) || error; });
    rethrow_locked();
  }

 private:
  void rethrow_locked() {
    if (error) std::rethrow_exception(error);
  }
  void serve() {
    for (;;) {
      std::function<void()> job;
      {
        std::unique_lock lock(m);
        cv_jobs.wait(lock, [&] { return stop || !jobs.empty(); });
        if (jobs.empty()) return;
        job = std::move(jobs.front());
        jobs.pop_front();
        ++busy;
      }
      std::exception_ptr e;
      try {
        job();
      } catch (...) {
        e = std::current_exception();
      }
      {
        std::lock_guard lock(m);
        --busy;
        if (e && !error) error = e;
      }
      cv_room.notify_all();
    }
  }

  std::size_t limit;
  std::mutex m;
  std::condition_variable cv_jobs, cv_room;
  std::deque<std::function<void()>> jobs;
  std::vector<std::thread> workers;
  std::size_t busy = 0;
  bool stop = false;
  std::exception_ptr error;
};

DatasetWriter::DatasetWriter(fs::path dir, DatasetInfo info, unsigned threads)
    : dir_(std::move(dir)), info_(std::move(info)) {
  info_.format_version = kFormatVersion;  // the only layout written
  if (threads == 0) threads = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
  encoder_ = std::make_unique<Encoder>(threads);
}
DatasetWriter::~DatasetWriter() = default;

AgentData& DatasetWriter::get(const std::string& agent) {
  for (auto& a : agents_)
    if (a.name == agent) return a;
  throw std::logic_error("dataset writer: unknown agent '" + agent + "'");
}

void DatasetWriter::add_agent(const std::string& name, const std::optional<CameraInfo>& camera) {
  AgentData a;
  a.name = name;
  a.camera = camera;
  fs::create_directories(layout_.agent(dir_, name));
  if (camera) {
    fs::create_directories(layout_.sensor(dir_, name, "cam0") / "data");
    fs::create_directories(layout_.sensor(dir_, name, "depth0") / "data");
  }
  agents_.push_back(std::move(a));
}

namespace {

// Encodes and writes a PNG; returns its size and CRC-32 for checksums.csv.
FrameChecksum write_png(const fs::path& p, const cv::Mat& img) {
  std::vector<unsigned char> buf;
  // Level 1: several times faster than the default and only slightly larger files.
  if (!cv::imencode(".png", img, buf, {cv::IMWRITE_PNG_COMPRESSION, 1}))
    throw std::runtime_error("cannot encode " + p.string());
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
  f.close();
  if (!f) throw std::runtime_error("cannot write " + p.string());
  return {static_cast<std::uint64_t>(buf.size()), crc32_of(buf.data(), buf.size())};
}

template <typename Row>
void write_csv(const fs::path& p, const std::string& header, std::size_t n, Row row) {
  fs::create_directories(p.parent_path());
  auto out = fmt::output_file(p.string());
  out.print("{}\n", header);
  for (std::size_t i = 0; i < n; ++i) out.print("{}\n", row(i));
  out.close();
}

void write_yaml(const fs::path& p, const YAML::Emitter& e) {
  std::ofstream f(p);
  f << e.c_str() << "\n";
  if (!f) throw std::runtime_error("cannot write " + p.string());
}

template <typename V>
void seq(YAML::Emitter& e, const V& v) {
  e << YAML::Flow << YAML::BeginSeq;
  for (auto x : v) e << x;
  e << YAML::EndSeq;
}

}  // namespace

void DatasetWriter::write_frame(const std::string& agent, std::int64_t t_ns, const cv::Mat& rgb,
                                const cv::Mat& depth) {
  AgentData& a = get(agent);
  if (!a.camera) throw std::logic_error("dataset writer: agent '" + agent + "' has no camera");
  const std::string file = fmt::format("{}.png", t_ns);
  const bool gray = a.camera->channels == 1;
  const fs::path colour_path = layout_.sensor(dir_, agent, "cam0") / "data" / file;
  const fs::path depth_path = layout_.sensor(dir_, agent, "depth0") / "data" / file;
  // Converted here (cheap), encoded on a worker (costly); the job owns its images.
  cv::Mat out;
  cv::cvtColor(rgb, out, gray ? cv::COLOR_RGB2GRAY : cv::COLOR_RGB2BGR);
  cv::Mat mm;
  // Metres to millimetres; 0 (no surface) stays 0 and anything beyond 65.535 m becomes 0 too
  // rather than a wrong, saturated distance.
  cv::Mat valid = (depth > 0) & (depth < 65.5355);
  depth.convertTo(mm, CV_16U, 1.0 / kDepthScale);
  mm.setTo(0, ~valid);
  const std::string colour_rel = layout_.frame_relative(agent, false, t_ns),
                    depth_rel = layout_.frame_relative(agent, true, t_ns);
  encoder_->push([this, out, mm, colour_path, depth_path, colour_rel, depth_rel] {
    const FrameChecksum c = write_png(colour_path, out), d = write_png(depth_path, mm);
    std::lock_guard lock(checksums_mutex_);
    checksums_[colour_rel] = c;
    checksums_[depth_rel] = d;
  });
  a.frames.push_back(t_ns);
}

void DatasetWriter::ground_truth(const std::string& agent, const PoseSample& s) { get(agent).groundtruth.push_back(s); }
void DatasetWriter::camera_pose(const std::string& agent, const PoseSample& s) { get(agent).camera_pose.push_back(s); }
void DatasetWriter::lead_label(const std::string& agent, const LeadLabel& s) { get(agent).lead_labels.push_back(s); }
void DatasetWriter::gps(const std::string& agent, const Vec3Sample& s) { get(agent).gps.push_back(s); }
void DatasetWriter::altimeter(const std::string& agent, const ScalarSample& s) { get(agent).altimeter.push_back(s); }
void DatasetWriter::range(const std::string& agent, const ScalarSample& s) { get(agent).range.push_back(s); }
void DatasetWriter::ahrs(const std::string& agent, const ScalarSample& s) { get(agent).ahrs.push_back(s); }
void DatasetWriter::exposure(const std::string& agent, const ExposureSample& s) { get(agent).exposure.push_back(s); }
void DatasetWriter::imu_info(const std::string& agent, const ImuInfo& info) { get(agent).imu_info = info; }
void DatasetWriter::imu(const std::string& agent, const ImuSample& s) { get(agent).imu.push_back(s); }

namespace {

std::string g(double x) { return fmt::format("{:.9g}", x + 0.0); }  // + 0.0: no "-0"

// EuRoC's extrinsics block: T_BS, the sensor's pose in the body frame, a row-major 4x4.
void emit_T_BS(YAML::Emitter& e, const Eigen::Matrix3d& R_BS, const Eigen::Vector3d& p_BS) {
  std::vector<double> data;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) data.push_back(R_BS(i, j) + 0.0);
    data.push_back(p_BS(i) + 0.0);
  }
  for (double x : {0.0, 0.0, 0.0, 1.0}) data.push_back(x);
  e << YAML::Key << "T_BS" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "cols" << YAML::Value << 4 << YAML::Key << "rows" << YAML::Value << 4;
  e << YAML::Key << "data" << YAML::Value;
  seq(e, data);
  e << YAML::EndMap;
}

// A sensor.yaml's opening keys, in EuRoC's order.
void emit_sensor_head(YAML::Emitter& e, const char* type, const std::string& comment,
                      const Eigen::Matrix3d& R_BS = Eigen::Matrix3d::Identity(),
                      const Eigen::Vector3d& p_BS = Eigen::Vector3d::Zero()) {
  e.SetDoublePrecision(15);
  e << YAML::BeginMap;
  e << YAML::Key << "sensor_type" << YAML::Value << type;
  e << YAML::Key << "comment" << YAML::Value << comment;
  emit_T_BS(e, R_BS, p_BS);
}

// The shutter, with what a loader needs for each row's time and pose; the sensor when it is physical.
void emit_shutter(YAML::Emitter& e, const CameraInfo& c) {
  e << YAML::Key << "shutter" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "type" << YAML::Value << (c.rolling ? "rolling" : "global");
  e << YAML::Key << "exposure_s" << YAML::Value << c.exposure_s;  // the first frame's
  if (c.exposed()) e << YAML::Key << "exposure_per_frame" << YAML::Value << "exposure.csv";
  e << YAML::Key << "line_delay_s" << YAML::Value << (c.rolling ? c.line_delay_s : 0.0);
  e << YAML::Key << "readout" << YAML::Value << (c.top_to_bottom ? "top_to_bottom" : "bottom_to_top");
  e << YAML::Key << "row_time" << YAML::Value
    << "a frame's time stamp is the middle of the exposure of row (h - 1) / 2; row r's is that plus "
       "(r - (h - 1) / 2) * line_delay_s (top_to_bottom) or minus it (bottom_to_top); its pose is the "
       "camera's then (cam0_pose0 holds the middle row's)";
  e << YAML::EndMap;
  if (c.sensor.empty()) return;
  e << YAML::Key << "sensor" << YAML::Value << YAML::BeginMap;
  for (const auto& [k, v] : c.sensor) e << YAML::Key << k << YAML::Value << v;
  e << YAML::EndMap;
}

// cam0 or depth0: the camera's nominal mount (T_BS: the commanded attitude at body yaw 0, the
// offset d) and its intrinsics. Radial-tangential takes four coefficients; a lens with k3 is
// written as ROS's plumb_bob (k1, k2, p1, p2, k3).
void write_camera_yaml(const fs::path& p, const CameraInfo& c, bool depth) {
  YAML::Emitter e;
  emit_sensor_head(e, depth ? "depth" : "camera",
                   depth ? "metric depth along the optical axis of cam0, 16-bit PNG; value * depth_scale = metres, 0 = none"
                         : "pinhole camera on a world-stabilised gimbal; pixel (0,0) is the centre of the top-left "
                           "pixel; the true pose of every frame (gimbal error included) is in cam0_pose0",
                   c.R_CW.transpose(), c.offset);
  e << YAML::Key << "rate_hz" << YAML::Value << c.rate;
  e << YAML::Key << "resolution" << YAML::Value;
  seq(e, std::vector<int>{c.camera.width(), c.camera.height()});
  e << YAML::Key << "camera_model" << YAML::Value << "pinhole";
  e << YAML::Key << "intrinsics" << YAML::Value;
  seq(e, std::vector<double>{c.camera.fx(), c.camera.fy(), c.camera.cx(), c.camera.cy()});
  const auto& k = c.camera.distortion();
  const bool radtan = k.k3 == 0;
  e << YAML::Key << "distortion_model" << YAML::Value << (radtan ? "radial-tangential" : "plumb_bob");
  e << YAML::Key << "distortion_coefficients" << YAML::Value;
  seq(e, radtan ? std::vector<double>{k.k1, k.k2, k.p1, k.p2} : std::vector<double>{k.k1, k.k2, k.p1, k.p2, k.k3});
  emit_shutter(e, c);
  if (depth) {
    e << YAML::Key << "depth_scale" << YAML::Value << kDepthScale;
    e << YAML::Key << "encoding" << YAML::Value << "mono16";
  } else {
    e << YAML::Key << "encoding" << YAML::Value << (c.channels == 1 ? "mono8" : "rgb8");
  }
  e << YAML::EndMap;
  write_yaml(p, e);
}

void write_plain_yaml(const fs::path& p, const char* type, const std::string& comment,
                      const std::function<void(YAML::Emitter&)>& more = {}) {
  YAML::Emitter e;
  emit_sensor_head(e, type, comment);
  if (more) more(e);
  e << YAML::EndMap;
  write_yaml(p, e);
}

void write_imu(const fs::path& folder, const AgentData& a) {
  if (!a.imu_info) return;
  const ImuInfo& n = *a.imu_info;
  write_csv(folder / "data.csv", kImuHeader, a.imu.size(), [&](std::size_t i) {
    const auto& s = a.imu[i];
    return fmt::format("{},{},{},{},{},{},{}", s.t_ns, g(s.w_S.x()), g(s.w_S.y()), g(s.w_S.z()), g(s.a_S.x()),
                       g(s.a_S.y()), g(s.a_S.z()));
  });
  write_plain_yaml(folder / "sensor.yaml", "imu",
                   "simulated strapdown IMU at the body's origin, axes the body's; biases in "
                   "state_groundtruth_estimate0",
                   [&](YAML::Emitter& e) {
                     e << YAML::Key << "rate_hz" << YAML::Value << n.rate;
                     e << YAML::Key << "gyroscope_noise_density" << YAML::Value << n.gyroscope_noise_density;
                     e << YAML::Key << "gyroscope_random_walk" << YAML::Value << n.gyroscope_random_walk;
                     e << YAML::Key << "accelerometer_noise_density" << YAML::Value << n.accelerometer_noise_density;
                     e << YAML::Key << "accelerometer_random_walk" << YAML::Value << n.accelerometer_random_walk;
                   });
}

void write_poses(const fs::path& mav0, const AgentData& a) {
  write_csv(mav0 / "state_groundtruth_estimate0" / "data.csv", kGroundTruthHeader, a.groundtruth.size(),
            [&](std::size_t i) {
              const auto& s = a.groundtruth[i];
              return fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", s.t_ns, g(s.p.x()),
                                 g(s.p.y()), g(s.p.z()), g(s.q_xyzw.w()), g(s.q_xyzw.x()), g(s.q_xyzw.y()),
                                 g(s.q_xyzw.z()), g(s.v.x()), g(s.v.y()), g(s.v.z()), g(s.b_w.x()), g(s.b_w.y()),
                                 g(s.b_w.z()), g(s.b_a.x()), g(s.b_a.y()), g(s.b_a.z()));
            });
  write_plain_yaml(mav0 / "state_groundtruth_estimate0" / "sensor.yaml", "groundtruth",
                   "exact truth of the simulation: the body's pose in the world (p_WB, q_WB), its velocity "
                   "in the world frame and the IMU's biases (0 without an IMU)");
  if (a.camera_pose.empty()) return;
  // Stored in memory as R_CW (world to camera); on disk as the camera's pose in the world, T_WC.
  write_csv(mav0 / "cam0_pose0" / "data.csv", kCameraPoseHeader, a.camera_pose.size(), [&](std::size_t i) {
    const auto& s = a.camera_pose[i];
    return fmt::format("{},{},{},{},{},{},{},{}", s.t_ns, g(s.p.x()), g(s.p.y()), g(s.p.z()), g(s.q_xyzw.w()),
                       g(-s.q_xyzw.x()), g(-s.q_xyzw.y()), g(-s.q_xyzw.z()));
  });
  write_plain_yaml(mav0 / "cam0_pose0" / "sensor.yaml", "pose",
                   "true pose of cam0 in the world (T_WC, gimbal error included) at every frame");
}

void write_scalar(const fs::path& folder, const char* header, const std::vector<ScalarSample>& v,
                  const char* comment) {
  if (v.empty()) return;
  write_csv(folder / "data.csv", header, v.size(),
            [&](std::size_t i) { return fmt::format("{},{}", v[i].t_ns, g(v[i].value)); });
  write_plain_yaml(folder / "sensor.yaml", "scalar", comment);
}

void write_sensors(const fs::path& mav0, const AgentData& a) {
  if (!a.gps.empty()) {
    write_csv(mav0 / "gps0" / "data.csv", "#timestamp [ns],p_W_x [m],p_W_y [m],p_W_z [m]", a.gps.size(),
              [&](std::size_t i) {
                const auto& s = a.gps[i];
                return fmt::format("{},{},{},{}", s.t_ns, g(s.value.x()), g(s.value.y()), g(s.value.z()));
              });
    write_plain_yaml(mav0 / "gps0" / "sensor.yaml", "gps",
                     "position fix in the world frame (local metres, z up), white noise (paper eq. 7)");
  }
  write_scalar(mav0 / "altimeter0", "#timestamp [ns],z [m]", a.altimeter,
               "altitude of the body above the world's z = 0 (paper eq. 8)");
  write_scalar(mav0 / "range0", "#timestamp [ns],range to lead [m]", a.range,
               "distance from the body to the lead's reference point (paper eq. 9)");
  write_scalar(mav0 / "ahrs0", "#timestamp [ns],yaw [rad]", a.ahrs, "yaw of the body about z, noisy");
}

void write_frames(const fs::path& mav0, const AgentData& a) {
  for (const char* s : {"cam0", "depth0"})
    write_csv(mav0 / s / "data.csv", kFramesHeader, a.frames.size(),
              [&](std::size_t i) { return fmt::format("{},{}.png", a.frames[i], a.frames[i]); });
  write_camera_yaml(mav0 / "cam0" / "sensor.yaml", *a.camera, false);
  if (a.camera->exposed())
    write_csv(mav0 / "cam0" / "exposure.csv", "#timestamp [ns],exposure [s],gain", a.exposure.size(),
              [&](std::size_t i) {
                const auto& x = a.exposure[i];
                return fmt::format("{},{},{}", x.t_ns, g(x.exposure_s), g(x.gain));
              });
  write_camera_yaml(mav0 / "depth0" / "sensor.yaml", *a.camera, true);
  if (a.lead_labels.empty()) return;
  write_csv(mav0 / "cam0_lead0" / "data.csv", kLeadLabelHeader, a.lead_labels.size(), [&](std::size_t i) {
    const auto& x = a.lead_labels[i].lead;
    return fmt::format("{},{},{},{},{},{},{},{},{}", a.lead_labels[i].t_ns, g(x.uv.x()), g(x.uv.y()), g(x.distance),
                       g(x.visible), x.box_u0, x.box_v0, x.box_u1, x.box_v1);
  });
  write_plain_yaml(mav0 / "cam0_lead0" / "sensor.yaml", "lead_label",
                   "the lead in cam0's frames: x_h's projection (its row's pose), its distance, the visible share "
                   "of its silhouette and the visible pixels' box");
}

// One agent's folder (<agent>/mav0), everything but the images.
void write_agent(const fs::path& mav0, const AgentData& a) {
  write_poses(mav0, a);
  write_sensors(mav0, a);
  write_imu(mav0 / "imu0", a);
  if (a.camera) write_frames(mav0, a);
}

}  // namespace

void DatasetWriter::finish() {
  encoder_->drain();
  for (const AgentData& a : agents_) write_agent(layout_.agent(dir_, a.name), a);
  std::vector<std::pair<std::string, FrameChecksum>> sums(checksums_.begin(), checksums_.end());
  write_csv(dir_ / kChecksumsFile, "#file,bytes,crc32", sums.size(), [&](std::size_t i) {
    return fmt::format("{},{},{:08x}", sums[i].first, sums[i].second.bytes, sums[i].second.crc32);
  });
  for (const auto& a : agents_)
    if (a.camera) info_.frames = static_cast<int>(a.frames.size());
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << "wingman-dataset";
  e << YAML::Key << "format_version" << YAML::Value << info_.format_version;
  e << YAML::Key << "scenario" << YAML::Value << info_.scenario;
  e << YAML::Key << "variant" << YAML::Value << info_.variant;
  e << YAML::Key << "seed" << YAML::Value << info_.seed;
  e << YAML::Key << "software_version" << YAML::Value << info_.software_version;
  e << YAML::Key << "rate_hz" << YAML::Value << info_.rate;
  e << YAML::Key << "frames" << YAML::Value << info_.frames;
  e << YAML::Key << "renderer" << YAML::Value << info_.renderer;
  std::vector<std::string> names;
  for (const auto& a : agents_) names.push_back(a.name);
  e << YAML::Key << "agents" << YAML::Value;
  seq(e, names);
  e << YAML::EndMap;
  write_yaml(dir_ / "dataset.yaml", e);
}

}  // namespace wingman::datasets
