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
#include <tuple>

#include "datasets/frame_poses.hpp"

namespace wingman::frontend_bench {

namespace fs = std::filesystem;

namespace {

// pairs.csv's header; files without the condition column hold reference pairs only.
constexpr const char* kPairsHeader = "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition";
constexpr const char* kPairsHeaderReference = "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m";

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

// Frame A from the reference, frame B from its condition's dataset.
double baseline(const Conditions& sets, const FramePair& p) {
  return (camera_centre(sets.reference().agent(p.agent_a), p.t_a) -
          camera_centre(sets.find(p.condition)->agent(p.agent_b), p.t_b)).norm();
}

// The pairs with frame B under `condition` (from `b_ds`), appended: per start frame, each UAV's
// same-instant pair (a condition only), its temporal pairs per gap, then the cross pairs.
void append_pairs(const datasets::Dataset& ref, const datasets::Dataset& b_ds, const std::string& condition,
                  const PairOptions& o, std::vector<FramePair>& pairs) {
  std::vector<const datasets::AgentData*> uavs;
  for (const auto& a : ref.agents)
    if (a.camera && !a.frames.empty()) uavs.push_back(&a);
  std::size_t n = 0;
  for (const auto* a : uavs) n = std::max(n, a->frames.size());
  auto add = [&](const datasets::AgentData& a, std::size_t ka, const std::string& agent_b, std::size_t kb,
                 PairType type) {
    const datasets::AgentData& b = b_ds.agent(agent_b);
    FramePair p{static_cast<int>(pairs.size()), a.name, a.frames[ka], b.name, b.frames[kb], type, 0, condition};
    p.baseline_m = (a.camera_pose[ka].p - b.camera_pose[kb].p).norm();
    pairs.push_back(p);
  };
  for (std::size_t k = 0; k < n; k += static_cast<std::size_t>(o.stride)) {
    for (const auto* a : uavs) {
      if (condition != kReference && k < a->frames.size()) add(*a, k, a->name, k, PairType::SameInstant);
      for (int gap : o.gaps)
        if (k + static_cast<std::size_t>(gap) < a->frames.size()) add(*a, k, a->name, k + gap, PairType::Temporal);
    }
    if (!o.cross) continue;
    for (std::size_t i = 0; i < uavs.size(); ++i)
      for (std::size_t j = i + 1; j < uavs.size(); ++j)
        if (k < uavs[i]->frames.size() && k < uavs[j]->frames.size() &&
            uavs[i]->frames[k] == uavs[j]->frames[k])
          add(*uavs[i], k, uavs[j]->name, k, PairType::Cross);
  }
}

PairType parse_type(const std::string& s, const fs::path& file, int line) {
  for (const PairType t : kPairTypes)
    if (s == to_string(t)) return t;
  fail(file, line, fmt::format("type must be temporal, cross or same-instant, got '{}'", s));
}

// A pair's condition, frames and type against the datasets.
void check_pair(const FramePair& p, const Conditions& sets, const fs::path& file, int line) {
  const datasets::Dataset* b_ds = sets.find(p.condition);
  if (!b_ds)
    fail(file, line, fmt::format("condition '{}' is none of the datasets given ({}; a condition is given as "
                                 "--condition NAME=DIR)", p.condition, sets.names()));
  if (p.type == PairType::SameInstant && (p.condition == kReference || p.agent_a != p.agent_b || p.t_a != p.t_b))
    fail(file, line, "a same-instant pair is one UAV's frame at one time stamp under a condition other than the reference");
  try {
    for (const auto& [ds, agent, t] : {std::tuple{&sets.reference(), p.agent_a, p.t_a}, std::tuple{b_ds, p.agent_b, p.t_b}}) {
      const auto& a = ds->agent(agent);
      if (!a.camera) throw datasets::DatasetError(fmt::format("agent {} has no camera", agent));
      frame_index(a, t);
    }
  } catch (const datasets::DatasetError& e) {
    const std::string which = p.condition == kReference ? "" : " or " + b_ds->root.string();
    fail(file, line, fmt::format("names a frame the dataset {}{} lacks: {}", sets.reference().root.string(), which, e.what()));
  }
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

const char* to_string(PairType t) {
  switch (t) {
    case PairType::Temporal: return "temporal";
    case PairType::Cross: return "cross";
    case PairType::SameInstant: return "same-instant";
  }
  return "?";
}

void PairOptions::validate() const {
  if (stride < 1) throw std::invalid_argument(fmt::format("pair stride must be >= 1, got {}", stride));
  for (int g : gaps)
    if (g < 1) throw std::invalid_argument(fmt::format("temporal gap must be >= 1 frame, got {}", g));
}

std::vector<FramePair> make_pairs(const Conditions& sets, const PairOptions& o) {
  o.validate();
  std::vector<FramePair> pairs;
  append_pairs(sets.reference(), sets.reference(), kReference, o, pairs);
  for (const auto& c : sets.conditions()) append_pairs(sets.reference(), c.dataset, c.name, o, pairs);
  return pairs;
}

std::vector<FramePair> make_pairs(const datasets::Dataset& ds, const PairOptions& o) {
  return make_pairs(Conditions(ds), o);
}

std::string pairs_csv(const std::vector<FramePair>& pairs) {
  std::string s = std::string(kPairsHeader) + "\n";
  for (const auto& p : pairs)
    s += fmt::format("{},{},{},{},{},{},{:.4f},{}\n", p.id, p.agent_a, p.t_a, p.agent_b, p.t_b,
                     to_string(p.type), p.baseline_m, p.condition);
  return s;
}

std::vector<FramePair> read_pairs(const fs::path& file, const Conditions& sets) {
  std::vector<FramePair> pairs;
  std::set<int> ids;
  read_csv(file, {kPairsHeader, kPairsHeaderReference}, [&](const std::vector<std::string>& f, int line, int header) {
    expect_fields(f, header == 0 ? 8 : 7, file, line);
    FramePair p;
    p.id = parse<int>(f[0], file, line, "pair_id");
    if (p.id < 0 || !ids.insert(p.id).second)
      fail(file, line, fmt::format("pair_id {} is negative or repeated", p.id));
    p.agent_a = f[1];
    p.t_a = parse<std::int64_t>(f[2], file, line, "t_ns_a");
    p.agent_b = f[3];
    p.t_b = parse<std::int64_t>(f[4], file, line, "t_ns_b");
    p.type = parse_type(f[5], file, line);
    if (header == 0) p.condition = f[7];
    check_pair(p, sets, file, line);
    p.baseline_m = baseline(sets, p);
    pairs.push_back(p);
  });
  return pairs;
}

std::vector<FramePair> read_pairs(const fs::path& file, const datasets::Dataset& ds) {
  return read_pairs(file, Conditions(ds));
}

FrameTruth frame_truth(const datasets::Dataset& ds, const std::string& agent, std::int64_t t_ns) {
  const auto& a = ds.agent(agent);
  if (!a.camera) throw datasets::DatasetError(fmt::format("agent {} has no camera", agent));
  FrameTruth f;
  f.camera = a.camera->camera;
  f.pose = datasets::frame_poses(a, frame_index(a, t_ns));
  f.depth = ds.load_depth(agent, t_ns);
  return f;
}

fs::path keypoints_file(const fs::path& dir, const std::string& agent, std::int64_t t_ns) {
  return dir / "keypoints" / agent / (std::to_string(t_ns) + ".csv");
}

fs::path keypoints_file(const fs::path& dir, const std::string& condition, const std::string& agent,
                        std::int64_t t_ns) {
  return condition == kReference ? keypoints_file(dir, agent, t_ns)
                                 : keypoints_file(dir / "conditions" / condition, agent, t_ns);
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
  using Frame = std::tuple<std::string, std::string, std::int64_t>;  // condition, agent, t_ns
  std::map<Frame, double> ms;
  read_csv(file, {"agent,t_ns,ms", "condition,agent,t_ns,ms"}, [&](const std::vector<std::string>& f, int line, int header) {
    expect_fields(f, header == 0 ? 3 : 4, file, line);
    const std::size_t k = header == 0 ? 0 : 1;  // the agent's field
    const double v = parse<double>(f[k + 2], file, line, "ms");
    if (v < 0) fail(file, line, fmt::format("ms {} is negative", v));
    ms[{header == 0 ? std::string(kReference) : f[0], f[k], parse<std::int64_t>(f[k + 1], file, line, "t_ns")}] = v;
  });
  std::set<Frame> frames;
  for (const auto& p : pairs) frames.insert({kReference, p.agent_a, p.t_a}), frames.insert({p.condition, p.agent_b, p.t_b});
  double sum = 0;
  for (const auto& key : frames) {
    const auto it = ms.find(key);
    if (it == ms.end())
      fail(file, 0, fmt::format("no time for frame {} {}{} of the pairs", std::get<1>(key), std::get<2>(key),
                                std::get<0>(key) == kReference ? "" : " under condition " + std::get<0>(key)));
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
