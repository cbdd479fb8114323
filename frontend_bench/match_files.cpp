#include "frontend_bench/match_files.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>


namespace wingman::frontend_bench {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const fs::path& file, int line, const std::string& what) {
  if (line > 0) throw MatchInputError(fmt::format("{}:{}: {}", file.string(), line, what));
  throw MatchInputError(fmt::format("{}: {}", file.string(), what));
}

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r");
  const auto e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) out.push_back(trim(f));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// A CSV file read row by row: the header must be one of `headers`; blank lines and lines
// starting with '#' are skipped. `row(fields, line)` gets each data row.
template <class Row>
int read_csv(const fs::path& file, const std::vector<std::string>& headers, Row row) {
  std::ifstream in(file);
  if (!in) fail(file, 0, fs::exists(file) ? "cannot be read" : "missing");
  int line_no = 0, header = -1;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    if (header < 0) {
      const auto it = std::find(headers.begin(), headers.end(), line);
      if (it == headers.end())
        fail(file, line_no, fmt::format("header must be '{}', got '{}'", fmt::join(headers, "' or '"), line));
      header = static_cast<int>(it - headers.begin());
      continue;
    }
    row(split(line), line_no, header);
  }
  if (header < 0) fail(file, 0, fmt::format("empty: a header '{}' is needed", headers[0]));
  return header;
}

template <class T>
T parse(const std::string& s, const fs::path& file, int line, const char* what) {
  T v{};
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty())
    fail(file, line, fmt::format("{} '{}' is not a {}", what, s,
                                 std::is_integral_v<T> ? "whole number" : "number"));
  if constexpr (std::is_floating_point_v<T>)
    if (!std::isfinite(v)) fail(file, line, fmt::format("{} '{}' is not finite", what, s));
  return v;
}

void expect_fields(const std::vector<std::string>& f, std::size_t n, const fs::path& file, int line) {
  if (f.size() != n) fail(file, line, fmt::format("expected {} fields, got {}", n, f.size()));
}

std::size_t frame_index(const datasets::AgentData& a, std::int64_t t_ns) {
  const auto it = std::lower_bound(a.frames.begin(), a.frames.end(), t_ns);
  if (it == a.frames.end() || *it != t_ns)
    throw datasets::DatasetError(fmt::format("{}: agent {} has no frame at t_ns {}",
                                             a.name, a.name, t_ns));
  return static_cast<std::size_t>(it - a.frames.begin());
}

Eigen::Vector3d camera_centre(const datasets::AgentData& a, std::int64_t t_ns) {
  return a.camera_pose.at(frame_index(a, t_ns)).p;
}

double baseline(const datasets::Dataset& ds, const FramePair& p) {
  return (camera_centre(ds.agent(p.agent_a), p.t_a) - camera_centre(ds.agent(p.agent_b), p.t_b)).norm();
}

// Many small files: checked, but without the fsync of io::write_file_atomic (the caller stages the
// whole directory).
void write_text(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace

const char* to_string(PairType t) { return t == PairType::Temporal ? "temporal" : "cross"; }

void PairOptions::validate() const {
  if (stride < 1) throw std::invalid_argument(fmt::format("pair stride must be >= 1, got {}", stride));
  for (int g : gaps)
    if (g < 1) throw std::invalid_argument(fmt::format("temporal gap must be >= 1 frame, got {}", g));
}

std::vector<FramePair> make_pairs(const datasets::Dataset& ds, const PairOptions& o) {
  o.validate();
  std::vector<const datasets::AgentData*> uavs;
  for (const auto& a : ds.agents)
    if (a.camera && !a.frames.empty()) uavs.push_back(&a);
  std::size_t n = 0;
  for (const auto* a : uavs) n = std::max(n, a->frames.size());
  std::vector<FramePair> pairs;
  auto add = [&](const datasets::AgentData& a, std::size_t ka, const datasets::AgentData& b,
                 std::size_t kb, PairType type) {
    FramePair p{static_cast<int>(pairs.size()), a.name, a.frames[ka], b.name, b.frames[kb], type, 0};
    p.baseline_m = (a.camera_pose[ka].p - b.camera_pose[kb].p).norm();
    pairs.push_back(p);
  };
  for (std::size_t k = 0; k < n; k += static_cast<std::size_t>(o.stride)) {
    for (const auto* a : uavs)
      for (int gap : o.gaps)
        if (k + static_cast<std::size_t>(gap) < a->frames.size()) add(*a, k, *a, k + gap, PairType::Temporal);
    if (!o.cross) continue;
    for (std::size_t i = 0; i < uavs.size(); ++i)
      for (std::size_t j = i + 1; j < uavs.size(); ++j)
        if (k < uavs[i]->frames.size() && k < uavs[j]->frames.size() &&
            uavs[i]->frames[k] == uavs[j]->frames[k])
          add(*uavs[i], k, *uavs[j], k, PairType::Cross);
  }
  return pairs;
}

std::string pairs_csv(const std::vector<FramePair>& pairs) {
  std::string s = "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m\n";
  for (const auto& p : pairs)
    s += fmt::format("{},{},{},{},{},{},{:.4f}\n", p.id, p.agent_a, p.t_a, p.agent_b, p.t_b,
                     to_string(p.type), p.baseline_m);
  return s;
}

std::vector<FramePair> read_pairs(const fs::path& file, const datasets::Dataset& ds) {
  std::vector<FramePair> pairs;
  std::set<int> ids;
  read_csv(file, {"pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m"},
           [&](const std::vector<std::string>& f, int line, int) {
    expect_fields(f, 7, file, line);
    FramePair p;
    p.id = parse<int>(f[0], file, line, "pair_id");
    if (p.id < 0 || !ids.insert(p.id).second)
      fail(file, line, fmt::format("pair_id {} is negative or repeated", p.id));
    p.agent_a = f[1];
    p.t_a = parse<std::int64_t>(f[2], file, line, "t_ns_a");
    p.agent_b = f[3];
    p.t_b = parse<std::int64_t>(f[4], file, line, "t_ns_b");
    if (f[5] != "temporal" && f[5] != "cross")
      fail(file, line, fmt::format("type must be temporal or cross, got '{}'", f[5]));
    p.type = f[5] == "temporal" ? PairType::Temporal : PairType::Cross;
    try {
      for (const auto& [agent, t] : {std::pair{p.agent_a, p.t_a}, std::pair{p.agent_b, p.t_b}}) {
        const auto& a = ds.agent(agent);
        if (!a.camera) throw datasets::DatasetError(fmt::format("agent {} has no camera", agent));
        frame_index(a, t);
      }
    } catch (const datasets::DatasetError& e) {
      fail(file, line, fmt::format("names a frame the dataset {} lacks: {}", ds.root.string(), e.what()));
    }
    p.baseline_m = baseline(ds, p);
    pairs.push_back(p);
  });
  return pairs;
}

FrameTruth frame_truth(const datasets::Dataset& ds, const std::string& agent, std::int64_t t_ns) {
  const auto& a = ds.agent(agent);
  if (!a.camera) throw datasets::DatasetError(fmt::format("agent {} has no camera", agent));
  const auto& pose = a.camera_pose.at(frame_index(a, t_ns));
  FrameTruth f;
  f.camera = a.camera->camera;
  const Eigen::Quaterniond q(pose.q_xyzw[3], pose.q_xyzw[0], pose.q_xyzw[1], pose.q_xyzw[2]);
  f.R_CW = q.normalized().toRotationMatrix();
  f.centre = pose.p;
  f.depth = ds.load_depth(agent, t_ns);
  return f;
}

fs::path keypoints_file(const fs::path& dir, const std::string& agent, std::int64_t t_ns) {
  return dir / "keypoints" / agent / (std::to_string(t_ns) + ".csv");
}

fs::path matches_file(const fs::path& dir, int pair_id) {
  return dir / "matches" / (std::to_string(pair_id) + ".csv");
}

std::vector<Keypoint> read_keypoints(const fs::path& file, int width, int height) {
  std::vector<Keypoint> kps;
  read_csv(file, {"x,y", "x,y,score"}, [&](const std::vector<std::string>& f, int line, int header) {
    expect_fields(f, header == 0 ? 2 : 3, file, line);
    Keypoint k;
    k.uv = {parse<double>(f[0], file, line, "x"), parse<double>(f[1], file, line, "y")};
    if (header == 1) k.score = parse<double>(f[2], file, line, "score");
    if (k.uv.x() < -0.5 || k.uv.y() < -0.5 || k.uv.x() > width - 0.5 || k.uv.y() > height - 0.5)
      fail(file, line, fmt::format("keypoint ({}, {}) lies outside the {} x {} image", k.uv.x(),
                                   k.uv.y(), width, height));
    kps.push_back(k);
  });
  return kps;
}

std::vector<Match> read_matches(const fs::path& file, int n_a, int n_b) {
  std::vector<Match> matches;
  read_csv(file, {"index_a,index_b", "index_a,index_b,score"},
           [&](const std::vector<std::string>& f, int line, int header) {
    expect_fields(f, header == 0 ? 2 : 3, file, line);
    Match m{parse<int>(f[0], file, line, "index_a"), parse<int>(f[1], file, line, "index_b")};
    if (header == 1) parse<double>(f[2], file, line, "score");
    if (m.a < 0 || m.a >= n_a)
      fail(file, line, fmt::format("index_a {} out of range: frame A has {} keypoints", m.a, n_a));
    if (m.b < 0 || m.b >= n_b)
      fail(file, line, fmt::format("index_b {} out of range: frame B has {} keypoints", m.b, n_b));
    matches.push_back(m);
  });
  return matches;
}

std::optional<double> mean_frame_ms(const fs::path& dir, const std::vector<FramePair>& pairs) {
  const fs::path file = dir / "timings.csv";
  if (!fs::exists(file)) return std::nullopt;
  std::map<std::pair<std::string, std::int64_t>, double> ms;
  read_csv(file, {"agent,t_ns,ms"}, [&](const std::vector<std::string>& f, int line, int) {
    expect_fields(f, 3, file, line);
    const double v = parse<double>(f[2], file, line, "ms");
    if (v < 0) fail(file, line, fmt::format("ms {} is negative", v));
    ms[{f[0], parse<std::int64_t>(f[1], file, line, "t_ns")}] = v;
  });
  std::set<std::pair<std::string, std::int64_t>> frames;
  for (const auto& p : pairs) frames.insert({p.agent_a, p.t_a}), frames.insert({p.agent_b, p.t_b});
  double sum = 0;
  for (const auto& key : frames) {
    const auto it = ms.find(key);
    if (it == ms.end()) fail(file, 0, fmt::format("no time for frame {} {} of the pairs", key.first, key.second));
    sum += it->second;
  }
  return frames.empty() ? std::nullopt : std::optional<double>(sum / static_cast<double>(frames.size()));
}

void write_keypoints(const fs::path& file, const std::vector<Keypoint>& keypoints) {
  std::string s = "x,y,score\n";
  for (const auto& k : keypoints) s += fmt::format("{:.3f},{:.3f},{:.6g}\n", k.uv.x(), k.uv.y(), k.score);
  write_text(file, s);
}

void write_matches(const fs::path& file, const std::vector<Match>& matches) {
  std::string s = "index_a,index_b\n";
  for (const auto& m : matches) s += fmt::format("{},{}\n", m.a, m.b);
  write_text(file, s);
}

}  // namespace wingman::frontend_bench
