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
  fs::create_directories(dir_ / name / "groundtruth");
  if (camera) {
    fs::create_directories(dir_ / name / "cam0" / "data");
    fs::create_directories(dir_ / name / "depth0" / "data");
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
  const fs::path colour_path = dir_ / agent / "cam0" / "data" / file;
  const fs::path depth_path = dir_ / agent / "depth0" / "data" / file;
  // Converted here (cheap), encoded on a worker (costly); the job owns its images.
  cv::Mat out;
  cv::cvtColor(rgb, out, gray ? cv::COLOR_RGB2GRAY : cv::COLOR_RGB2BGR);
  cv::Mat mm;
  // Metres to millimetres; 0 (no surface) stays 0 and anything beyond 65.535 m becomes 0 too
  // rather than a wrong, saturated distance.
  cv::Mat valid = (depth > 0) & (depth < 65.5355);
  depth.convertTo(mm, CV_16U, 1.0 / kDepthScale);
  mm.setTo(0, ~valid);
  const std::string colour_rel = agent + "/cam0/data/" + file, depth_rel = agent + "/depth0/data/" + file;
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
void DatasetWriter::gps(const std::string& agent, const Vec3Sample& s) { get(agent).gps.push_back(s); }
void DatasetWriter::altimeter(const std::string& agent, const ScalarSample& s) { get(agent).altimeter.push_back(s); }
void DatasetWriter::range(const std::string& agent, const ScalarSample& s) { get(agent).range.push_back(s); }
void DatasetWriter::ahrs(const std::string& agent, const ScalarSample& s) { get(agent).ahrs.push_back(s); }
void DatasetWriter::imu_info(const std::string& agent, const ImuInfo& info) { get(agent).imu_info = info; }
void DatasetWriter::imu(const std::string& agent, const ImuSample& s) { get(agent).imu.push_back(s); }

void DatasetWriter::finish() {
  encoder_->drain();
  const auto g = [](double x) { return fmt::format("{:.9g}", x + 0.0); };  // no "-0"
  for (const AgentData& a : agents_) {
    const fs::path d = dir_ / a.name;
    write_csv(d / "groundtruth" / "data.csv",
              "#timestamp [ns],p_x [m],p_y [m],p_z [m],q_w,q_x,q_y,q_z,v_x [m/s],v_y [m/s],v_z [m/s]",
              a.groundtruth.size(), [&](std::size_t i) {
                const auto& s = a.groundtruth[i];
                return fmt::format("{},{},{},{},{},{},{},{},{},{},{}", s.t_ns, g(s.p.x()), g(s.p.y()),
                                   g(s.p.z()), g(s.q_xyzw.w()), g(s.q_xyzw.x()), g(s.q_xyzw.y()),
                                   g(s.q_xyzw.z()), g(s.v.x()), g(s.v.y()), g(s.v.z()));
              });
    if (!a.camera_pose.empty())
      write_csv(d / "groundtruth" / "cam0.csv",
                "#timestamp [ns],c_x [m],c_y [m],c_z [m],q_CW_w,q_CW_x,q_CW_y,q_CW_z",
                a.camera_pose.size(), [&](std::size_t i) {
                  const auto& s = a.camera_pose[i];
                  return fmt::format("{},{},{},{},{},{},{},{}", s.t_ns, g(s.p.x()), g(s.p.y()),
                                     g(s.p.z()), g(s.q_xyzw.w()), g(s.q_xyzw.x()),
                                     g(s.q_xyzw.y()), g(s.q_xyzw.z()));
                });
    if (!a.gps.empty())
      write_csv(d / "gps0" / "data.csv", "#timestamp [ns],x [m],y [m],z [m]", a.gps.size(),
                [&](std::size_t i) {
                  const auto& s = a.gps[i];
                  return fmt::format("{},{},{},{}", s.t_ns, g(s.value.x()), g(s.value.y()), g(s.value.z()));
                });
    const auto scalar = [&](const char* folder, const char* header, const std::vector<ScalarSample>& v) {
      if (v.empty()) return;
      write_csv(d / folder / "data.csv", header, v.size(),
                [&](std::size_t i) { return fmt::format("{},{}", v[i].t_ns, g(v[i].value)); });
    };
    scalar("altimeter0", "#timestamp [ns],z [m]", a.altimeter);
    scalar("range0", "#timestamp [ns],range to lead [m]", a.range);
    scalar("ahrs0", "#timestamp [ns],yaw [rad]", a.ahrs);
    if (!a.camera) continue;
    for (const char* s : {"cam0", "depth0"})
      write_csv(d / s / "data.csv", "#timestamp [ns],filename", a.frames.size(),
                [&](std::size_t i) { return fmt::format("{},{}.png", a.frames[i], a.frames[i]); });
    const CameraInfo& c = *a.camera;
    const auto& k = c.camera.distortion();
    for (const bool depth : {false, true}) {
      YAML::Emitter e;
      e.SetDoublePrecision(15);
      e << YAML::BeginMap;
      e << YAML::Key << "sensor_type" << YAML::Value << (depth ? "depth" : "camera");
      e << YAML::Key << "comment" << YAML::Value
        << (depth ? "metric depth along the optical axis, 16-bit PNG, value * depth_scale = metres, 0 = none"
                  : "pinhole, OpenCV pixel convention (pixel (0,0) is the centre of the top-left pixel)");
      e << YAML::Key << "rate_hz" << YAML::Value << c.rate;
      e << YAML::Key << "resolution" << YAML::Value;
      seq(e, std::vector<int>{c.camera.width(), c.camera.height()});
      e << YAML::Key << "camera_model" << YAML::Value << "pinhole";
      e << YAML::Key << "intrinsics" << YAML::Value;
      seq(e, std::vector<double>{c.camera.fx(), c.camera.fy(), c.camera.cx(), c.camera.cy()});
      e << YAML::Key << "distortion_model" << YAML::Value << "radial-tangential";
      e << YAML::Key << "distortion_coefficients" << YAML::Value;
      seq(e, std::vector<double>{k.k1, k.k2, k.p1, k.p2, k.k3});
      e << YAML::Key << "R_CW" << YAML::Value;
      std::vector<double> r;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.push_back(c.R_CW(i, j));
      seq(e, r);
      e << YAML::Key << "offset" << YAML::Value;
      seq(e, std::vector<double>{c.offset.x(), c.offset.y(), c.offset.z()});
      if (depth) {
        e << YAML::Key << "depth_scale" << YAML::Value << kDepthScale;
        e << YAML::Key << "encoding" << YAML::Value << "png16";
      } else {
        e << YAML::Key << "channels" << YAML::Value << c.channels;
      }
      e << YAML::EndMap;
      write_yaml(d / (depth ? "depth0" : "cam0") / "sensor.yaml", e);
    }
  }
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
