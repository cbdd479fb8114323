#include "frontend_bench/match_score.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

namespace wingman::frontend_bench {

namespace fs = std::filesystem;

namespace {

double ratio(long num, long den) {
  return den > 0 ? static_cast<double>(num) / static_cast<double>(den)
                 : std::numeric_limits<double>::quiet_NaN();
}

// Distance from a pixel to the nearest of a set of keypoints, looked up in a grid whose cells are
// as wide as the largest threshold: beyond it the exact distance does not matter.
class NearestKeypoint {
 public:
  NearestKeypoint(const std::vector<Keypoint>& kps, double cell) : kps_(kps), cell_(cell) {
    for (std::size_t k = 0; k < kps.size(); ++k) grid_[key(cell_of(kps[k].uv.x()), cell_of(kps[k].uv.y()))].push_back(k);
  }
  // The distance, or infinity when none lies within one cell.
  double distance(const Eigen::Vector2d& uv) const {
    double best = std::numeric_limits<double>::infinity();
    const long cx = cell_of(uv.x()), cy = cell_of(uv.y());
    for (long dy = -1; dy <= 1; ++dy)
      for (long dx = -1; dx <= 1; ++dx) {
        const auto it = grid_.find(key(cx + dx, cy + dy));
        if (it == grid_.end()) continue;
        for (std::size_t k : it->second) best = std::min(best, (kps_[k].uv - uv).norm());
      }
    return best <= cell_ ? best : std::numeric_limits<double>::infinity();
  }

 private:
  long cell_of(double v) const { return static_cast<long>(std::floor(v / cell_)); }
  static long long key(long x, long y) { return (static_cast<long long>(x) << 32) ^ (y & 0xffffffffLL); }
  const std::vector<Keypoint>& kps_;
  double cell_;
  std::unordered_map<long long, std::vector<std::size_t>> grid_;
};

std::string bin_name(const std::vector<double>& edges, std::size_t i) {
  const double lo = i == 0 ? 0.0 : edges[i - 1];
  if (i == edges.size()) return fmt::format(">={:g} m", lo);
  return fmt::format("{:g}-{:g} m", lo, edges[i]);
}

std::size_t bin_of(const std::vector<double>& edges, double baseline) {
  return static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), baseline) - edges.begin());
}

// One condition's groups: all its pairs, then per type all baselines and each bin holding pairs.
void append_condition_groups(const std::string& condition, const std::vector<FramePair>& pairs,
                             const std::vector<MatchCounts>& counts, const ScoreOptions& o,
                             std::vector<GroupScore>& groups) {
  const std::size_t nt = o.thresholds_px.size(), nb = o.baseline_edges_m.size() + 1;
  const std::size_t first = groups.size();
  groups.push_back({condition, "all", "all", MatchCounts(nt)});
  for (const PairType type : kPairTypes) {
    GroupScore all{condition, to_string(type), "all", MatchCounts(nt)};
    std::vector<MatchCounts> bins(nb, MatchCounts(nt));
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (pairs[i].type != type || pairs[i].condition != condition) continue;
      all.counts.add(counts[i]);
      bins[bin_of(o.baseline_edges_m, pairs[i].baseline_m)].add(counts[i]);
    }
    if (all.counts.pairs == 0) continue;
    groups[first].counts.add(all.counts);
    groups.push_back(all);
    for (std::size_t k = 0; k < nb; ++k)
      if (bins[k].pairs > 0) groups.push_back({condition, to_string(type), bin_name(o.baseline_edges_m, k), bins[k]});
  }
  if (groups[first].counts.pairs == 0) groups.erase(groups.begin() + static_cast<long>(first));
}

}  // namespace

void ScoreOptions::validate() const {
  if (thresholds_px.empty()) throw std::invalid_argument("scoring needs at least one threshold");
  for (std::size_t i = 0; i < thresholds_px.size(); ++i)
    if (!(thresholds_px[i] > 0) || (i > 0 && thresholds_px[i] <= thresholds_px[i - 1]))
      throw std::invalid_argument("match thresholds must be positive and increasing");
  if (!(localisation_px > 0)) throw std::invalid_argument("localisation threshold must be > 0 px");
  for (std::size_t i = 0; i < baseline_edges_m.size(); ++i)
    if (!(baseline_edges_m[i] > 0) || (i > 0 && baseline_edges_m[i] <= baseline_edges_m[i - 1]))
      throw std::invalid_argument("baseline bin edges must be positive and increasing");
  correspondence.validate();
}

void MatchCounts::add(const MatchCounts& o) {
  if (o.repeatable.size() != repeatable.size()) throw std::invalid_argument("MatchCounts: thresholds differ");
  pairs += o.pairs;
  keypoints_a += o.keypoints_a;
  keypoints_b += o.keypoints_b;
  covisible += o.covisible;
  matches += o.matches;
  for (std::size_t i = 0; i < repeatable.size(); ++i) {
    repeatable[i] += o.repeatable[i];
    correct[i] += o.correct[i];
    correct_a[i] += o.correct_a[i];
  }
  localisation_sum_px += o.localisation_sum_px;
  localised += o.localised;
}

double MatchCounts::repeatability(std::size_t i) const { return ratio(repeatable.at(i), covisible); }
double MatchCounts::precision(std::size_t i) const { return ratio(correct.at(i), matches); }
double MatchCounts::recall(std::size_t i) const { return ratio(correct_a.at(i), repeatable.at(i)); }
double MatchCounts::localisation_px() const {
  return localised > 0 ? localisation_sum_px / static_cast<double>(localised)
                       : std::numeric_limits<double>::quiet_NaN();
}

MatchCounts score_pair(const FrameTruth& a, const FrameTruth& b, const std::vector<Keypoint>& kp_a,
                       const std::vector<Keypoint>& kp_b, const std::vector<Match>& matches,
                       const ScoreOptions& o) {
  const std::size_t nt = o.thresholds_px.size();
  MatchCounts c(nt);
  c.pairs = 1;
  c.keypoints_a = static_cast<long>(kp_a.size());
  c.keypoints_b = static_cast<long>(kp_b.size());
  c.matches = static_cast<long>(matches.size());
  const NearestKeypoint nearest(kp_b, o.thresholds_px.back());
  std::vector<Correspondence> truth(kp_a.size());
  for (std::size_t i = 0; i < kp_a.size(); ++i) {
    truth[i] = true_correspondence(a, b, kp_a[i].uv, o.correspondence);
    if (!truth[i].found()) continue;
    ++c.covisible;
    const double d = nearest.distance(truth[i].uv_b);
    for (std::size_t t = 0; t < nt; ++t) c.repeatable[t] += d <= o.thresholds_px[t];
  }
  // Recall counts distinct A keypoints: one matched twice is one correct correspondence.
  std::vector<std::vector<char>> matched(nt, std::vector<char>(kp_a.size(), 0));
  for (const Match& m : matches) {
    const Correspondence& t_a = truth.at(static_cast<std::size_t>(m.a));
    if (!t_a.found()) continue;
    const double e = (t_a.uv_b - kp_b.at(static_cast<std::size_t>(m.b)).uv).norm();
    for (std::size_t t = 0; t < nt; ++t) {
      if (e > o.thresholds_px[t]) continue;
      ++c.correct[t];
      char& seen = matched[t][static_cast<std::size_t>(m.a)];
      c.correct_a[t] += !seen;
      seen = 1;
    }
    if (e <= o.localisation_px) {
      c.localisation_sum_px += e;
      ++c.localised;
    }
  }
  return c;
}

namespace {

// Frames loaded once while consecutive pairs share them (pairs come in order of their first
// frame); the least recently used are dropped beyond a few dozen.
class FrameCache {
 public:
  FrameCache(const Conditions& sets, const fs::path& dir) : sets_(sets), dir_(dir) {}
  struct Frame {
    FrameTruth truth;
    std::vector<Keypoint> keypoints;
  };
  const Frame& get(const std::string& condition, const std::string& agent, std::int64_t t_ns) {
    const Key key{condition, agent, t_ns};
    if (const auto it = frames_.find(key); it != frames_.end()) {  // least recently used goes first
      order_.erase(std::find(order_.begin(), order_.end(), key));
      order_.push_back(key);
      return it->second;
    }
    if (order_.size() >= kMaxFrames) {
      frames_.erase(order_.front());
      order_.erase(order_.begin());
    }
    Frame f;
    f.truth = frame_truth(*sets_.find(condition), agent, t_ns);
    f.keypoints = read_keypoints(keypoints_file(dir_, condition, agent, t_ns), f.truth.camera.width(),
                                 f.truth.camera.height());
    order_.push_back(key);
    return frames_.emplace(key, std::move(f)).first->second;
  }

 private:
  static constexpr std::size_t kMaxFrames = 48;
  using Key = std::tuple<std::string, std::string, std::int64_t>;
  const Conditions& sets_;
  fs::path dir_;
  std::map<Key, Frame> frames_;
  std::vector<Key> order_;
};

}  // namespace

std::vector<MatchCounts> score_directory(const Conditions& sets, const std::vector<FramePair>& pairs,
                                         const fs::path& dir, const ScoreOptions& options,
                                         const std::function<void(int, int)>& progress) {
  options.validate();
  if (!fs::is_directory(dir)) throw MatchInputError(dir.string() + ": not a directory");
  FrameCache cache(sets, dir);
  std::vector<MatchCounts> out;
  out.reserve(pairs.size());
  for (const FramePair& p : pairs) {
    const auto& a = cache.get(kReference, p.agent_a, p.t_a);
    const auto& b = cache.get(p.condition, p.agent_b, p.t_b);
    const auto matches = read_matches(matches_file(dir, p.id), static_cast<int>(a.keypoints.size()),
                                      static_cast<int>(b.keypoints.size()));
    out.push_back(score_pair(a.truth, b.truth, a.keypoints, b.keypoints, matches, options));
    if (progress) progress(static_cast<int>(out.size()), static_cast<int>(pairs.size()));
  }
  return out;
}

std::vector<GroupScore> group_scores(const std::vector<FramePair>& pairs,
                                     const std::vector<MatchCounts>& counts, const ScoreOptions& o) {
  if (pairs.size() != counts.size()) throw std::invalid_argument("group_scores: one count per pair");
  std::vector<std::string> conditions{kReference};
  for (const auto& p : pairs)
    if (std::find(conditions.begin(), conditions.end(), p.condition) == conditions.end()) conditions.push_back(p.condition);
  std::vector<GroupScore> groups;
  for (const auto& c : conditions) append_condition_groups(c, pairs, counts, o, groups);
  return groups;
}

}  // namespace wingman::frontend_bench
