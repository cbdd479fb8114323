#include "frontend_bench/conditions.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>

namespace wingman::frontend_bench {

namespace fs = std::filesystem;

namespace {

// Row i of a dataset CSV is on line i + 2 (after its '#' header).
int csv_line(std::size_t i) { return static_cast<int>(i) + 2; }

std::vector<std::string> camera_agents(const datasets::Dataset& ds) {
  std::vector<std::string> names;
  for (const auto& a : ds.agents)
    if (a.camera) names.push_back(a.name);
  return names;
}

double pose_difference(const datasets::PoseSample& a, const datasets::PoseSample& b) {
  // q and -q are the same rotation.
  const double dq = std::min((a.q_xyzw - b.q_xyzw).cwiseAbs().maxCoeff(), (a.q_xyzw + b.q_xyzw).cwiseAbs().maxCoeff());
  return std::max((a.p - b.p).cwiseAbs().maxCoeff(), dq);
}

void check_agent(const datasets::Dataset& ref, const datasets::AgentData& r, const Condition& c) {
  const datasets::Dataset& ds = c.dataset;
  const datasets::AgentData& a = ds.agent(r.name);
  const std::string what = fmt::format("condition {} does not image the reference {}", c.name, ref.root.string());
  const fs::path cam0 = ds.layout.sensor(ds.root, a.name, "cam0");
  const auto& ca = a.camera->camera;
  const auto& cr = r.camera->camera;
  if (ca.width() != cr.width() || ca.height() != cr.height())
    throw datasets::DatasetError(fmt::format("{}: {}: its images are {} x {} px, the reference's {} x {}",
                                             (cam0 / "sensor.yaml").string(), what, ca.width(), ca.height(),
                                             cr.width(), cr.height()));
  const fs::path frames = cam0 / "data.csv";
  for (std::size_t i = 0; i < std::max(a.frames.size(), r.frames.size()); ++i) {
    if (i < a.frames.size() && i < r.frames.size() && a.frames[i] == r.frames[i]) continue;
    const std::string theirs = i < r.frames.size() ? std::to_string(r.frames[i]) : "none";
    const std::string ours = i < a.frames.size() ? std::to_string(a.frames[i]) : "none";
    throw datasets::DatasetError(fmt::format("{}:{}: {}: frame {} is at t_ns {}, the reference's at {}",
                                             frames.string(), csv_line(i), what, i, ours, theirs));
  }
  const fs::path poses = ds.layout.camera_pose_csv(ds.root, a.name);
  for (std::size_t i = 0; i < a.camera_pose.size(); ++i) {
    const double d = pose_difference(a.camera_pose[i], r.camera_pose[i]);
    if (!(d <= kPoseTolerance))
      throw datasets::DatasetError(fmt::format(
          "{}:{}: {}: the true camera pose at t_ns {} differs from the reference's by {:.3g} (more than {:g})",
          poses.string(), csv_line(i), what, a.frames[i], d, kPoseTolerance));
  }
}

constexpr std::size_t kMaxNameLength = 64;  // a condition names a folder of keypoints

bool name_ok(const std::string& s) {
  return !s.empty() && s.size() <= kMaxNameLength && std::all_of(s.begin(), s.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
  });
}

}  // namespace

void check_condition(const datasets::Dataset& ref, const Condition& c) {
  const auto ours = camera_agents(c.dataset), theirs = camera_agents(ref);
  if (ours != theirs)
    throw datasets::DatasetError(fmt::format(
        "{}: condition {} does not image the reference {}: its cameras are on [{}], the reference's on [{}]",
        (c.dataset.root / "dataset.yaml").string(), c.name, ref.root.string(), fmt::join(ours, ", "),
        fmt::join(theirs, ", ")));
  for (const auto& r : ref.agents)
    if (r.camera) check_agent(ref, r, c);
}

Conditions::Conditions(const datasets::Dataset& reference, std::vector<Condition> conditions)
    : reference_(&reference), conditions_(std::move(conditions)) {
  for (std::size_t i = 0; i < conditions_.size(); ++i) {
    const std::string& n = conditions_[i].name;
    if (!name_ok(n) || n == kReference)
      throw std::invalid_argument(fmt::format(
          "condition name '{}' must match [A-Za-z0-9_-]+ (at most {} characters) and not be '{}'", n, kMaxNameLength,
          kReference));
    for (std::size_t j = 0; j < i; ++j)
      if (conditions_[j].name == n) throw std::invalid_argument(fmt::format("condition '{}' given twice", n));
    check_condition(reference, conditions_[i]);
  }
}

const datasets::Dataset* Conditions::find(const std::string& name) const {
  if (name == kReference) return reference_;
  for (const auto& c : conditions_)
    if (c.name == name) return &c.dataset;
  return nullptr;
}

std::string Conditions::names() const {
  std::string s = kReference;
  for (const auto& c : conditions_) s += ", " + c.name;
  return s;
}

}  // namespace wingman::frontend_bench
