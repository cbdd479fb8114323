#include "frontend_bench/builtin_frontend.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <set>
#include <tuple>

namespace wingman::frontend_bench {

namespace fs = std::filesystem;

namespace {

// Features of the frames a few consecutive pairs share, detected once each.
class FeatureCache {
 public:
  FeatureCache(const Conditions& sets, const vision::FeatureExtractor& fx, const fs::path& dir,
               BuiltinFrontendRun& run)
      : sets_(sets), fx_(fx), dir_(dir), run_(run) {}
  const vision::Features& get(const std::string& condition, const std::string& agent, std::int64_t t_ns) {
    const Key key{condition, agent, t_ns};
    if (const auto it = cache_.find(key); it != cache_.end()) {
      order_.erase(std::find(order_.begin(), order_.end(), key));
      order_.push_back(key);
      return it->second;
    }
    if (order_.size() >= kMaxFrames) {
      cache_.erase(order_.front());
      order_.erase(order_.begin());
    }
    const cv::Mat image = sets_.find(condition)->load_image(agent, t_ns);
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    vision::Features f = fx_.detect(image);
    run_.detect_cpu_ms += 1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    run_.detect_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++run_.frames;
    run_.keypoints += f.size();
    if (!written_.count(key)) {  // a frame evicted and seen again is detected again, written once
      std::vector<Keypoint> kps;
      for (const auto& k : f.keypoints) kps.push_back({{k.pt.x, k.pt.y}, k.response});
      write_keypoints(keypoints_file(dir_, condition, agent, t_ns), kps);
      written_.insert(key);
    }
    order_.push_back(key);
    return cache_.emplace(key, std::move(f)).first->second;
  }

 private:
  static constexpr std::size_t kMaxFrames = 48;
  using Key = std::tuple<std::string, std::string, std::int64_t>;  // condition, agent, t_ns
  const Conditions& sets_;
  const vision::FeatureExtractor& fx_;
  fs::path dir_;
  BuiltinFrontendRun& run_;
  std::map<Key, vision::Features> cache_;
  std::vector<Key> order_;
  std::set<Key> written_;
};

}  // namespace

BuiltinFrontendRun run_builtin_frontend(const Conditions& sets,
                                        const std::vector<FramePair>& pairs,
                                        const BuiltinFrontendOptions& options, const fs::path& dir,
                                        const std::function<void(int, int)>& progress) {
  const vision::FeatureExtractor fx(options.features);
  BuiltinFrontendRun run;
  FeatureCache cache(sets, fx, dir, run);
  int done = 0;
  for (const auto& p : pairs) {
    const vision::Features& a = cache.get(kReference, p.agent_a, p.t_a);
    const vision::Features& b = cache.get(p.condition, p.agent_b, p.t_b);
    std::vector<Match> matches;
    for (const auto& m : vision::match_descriptors(a, b, options.matching)) matches.push_back({m.queryIdx, m.trainIdx});
    write_matches(matches_file(dir, p.id), matches);
    if (progress) progress(++done, static_cast<int>(pairs.size()));
  }
  return run;
}

}  // namespace wingman::frontend_bench
