// `wingman run --frame-cache` on rendered frames: a run that fills the cache, one that reads every
// frame back, another variant that shares the frames and one after an entry was damaged all give
// the results of a run without the cache (`wingman check --against`), and metrics.json says how
// the frames were got. Bad cache options are usage errors.
// GCC 12 warns falsely about std::string concatenation inlined from gtest (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"
#include "gl_required.hpp"

using namespace wingman::app::test;
using ::testing::HasSubstr;

namespace {

const fs::path kRenderedSmoke = kSourceDir / "scenes" / "rendered_smoke.yaml";

// A run of one named variant keeps it in <run>/<variant>.
nlohmann::json frame_cache_of(const fs::path& run, const std::string& variant = "multi") {
  return nlohmann::json::parse(read_file(run / variant / "metrics.json")).value("frame_cache", nlohmann::json());
}

RunResult run_smoke(const TempDir& tmp, const std::string& out, const std::string& variant,
                    const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args = {"run", kRenderedSmoke.string(), "--frames", "12", "--variant", variant,
                                   "--out", (tmp / out).string(), "--no-plots", "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return run_wingman(args, tmp.path());
}

void expect_same_results(const TempDir& tmp, const std::string& a, const std::string& b) {
  const RunResult r = run_wingman({"check", (tmp / a).string(), "--against", (tmp / b).string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("identical, timings aside")) << r.output;
}

TEST(FrameCacheCli, CachedRunsGiveTheUncachedResults) {
  if (std::string why; !wingman::testing::gl_available(&why)) WINGMAN_NO_GL_CONTEXT(why);
  TempDir tmp;
  const std::string cache = (tmp / "cache").string();
  ASSERT_EQ(run_smoke(tmp, "plain", "multi").exit_code, 0);
  ASSERT_EQ(run_smoke(tmp, "fill", "multi", {"--frame-cache", cache}).exit_code, 0);
  ASSERT_EQ(run_smoke(tmp, "hit", "multi", {"--frame-cache", cache}).exit_code, 0);
  expect_same_results(tmp, "plain", "fill");
  expect_same_results(tmp, "plain", "hit");
  EXPECT_TRUE(frame_cache_of(tmp / "plain").is_null());
  const auto fill = frame_cache_of(tmp / "fill"), hit = frame_cache_of(tmp / "hit");
  EXPECT_EQ(fill["misses"], 22);  // steps 1-11 of two cameras (step 0 has no frame), rendered and stored
  EXPECT_EQ(fill["stores"], 22);
  EXPECT_EQ(hit["hits"], 22);  // every one read back
  EXPECT_EQ(hit["misses"], 0);

  // The single-UAV variant flies the same camera: its frames are all in the cache already.
  ASSERT_EQ(run_smoke(tmp, "single_plain", "single").exit_code, 0);
  ASSERT_EQ(run_smoke(tmp, "single_hit", "single", {"--frame-cache", cache}).exit_code, 0);
  expect_same_results(tmp, "single_plain", "single_hit");
  EXPECT_EQ(frame_cache_of(tmp / "single_hit", "single")["hits"], 11);

  // A damaged entry is named, rendered again, and changes nothing.
  fs::path entry;
  for (const auto& e : fs::recursive_directory_iterator(cache))
    if (e.path().extension() == ".frame") entry = e.path();
  ASSERT_FALSE(entry.empty());
  {
    std::fstream io(entry, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(100000);
    io.put('\x42');
  }
  const RunResult damaged = run_smoke(tmp, "damaged", "multi", {"--frame-cache", cache});
  ASSERT_EQ(damaged.exit_code, 0) << damaged.output;
  EXPECT_THAT(damaged.output, HasSubstr(entry.string())) << damaged.output;
  EXPECT_THAT(damaged.output, HasSubstr("checksum mismatch")) << damaged.output;
  expect_same_results(tmp, "plain", "damaged");
  EXPECT_EQ(frame_cache_of(tmp / "damaged")["corrupt"], 1);
  EXPECT_EQ(frame_cache_of(tmp / "damaged")["stores"], 1);
}

TEST(FrameCacheCli, MonteCarloSharesOneCacheAndGivesTheUncachedStudy) {
  if (std::string why; !wingman::testing::gl_available(&why)) WINGMAN_NO_GL_CONTEXT(why);
  TempDir tmp;
  auto study = [&](const std::string& out, const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"montecarlo", kRenderedSmoke.string(), "--runs", "3", "--jobs", "2",
                                     "--frames", "6", "--out", (tmp / out).string(), "--no-plots", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_wingman(args, tmp.path());
  };
  ASSERT_EQ(study("plain", {"--no-frame-cache"}).exit_code, 0);
  const RunResult cached = study("cached", {});
  ASSERT_EQ(cached.exit_code, 0) << cached.output;
  expect_same_results(tmp, "plain", "cached");
  EXPECT_FALSE(fs::exists(tmp / "plain" / "frame_cache"));
  // The first seed rendered alone into <out>/frame_cache; every later run and variant read it.
  const fs::path runs = tmp / "cached" / "runs";
  EXPECT_EQ(frame_cache_of(runs / "seed1")["misses"], 10);  // steps 1-5, two cameras
  EXPECT_EQ(frame_cache_of(runs / "seed1", "single")["hits"], 5);
  for (const char* seed : {"seed2", "seed3"}) {
    EXPECT_EQ(frame_cache_of(runs / seed)["hits"], 10) << seed;
    EXPECT_EQ(frame_cache_of(runs / seed)["misses"], 0) << seed;
  }
  EXPECT_EQ(frame_cache_of(runs / "seed1")["dir"], (tmp / "cached" / "frame_cache").string());
  const RunResult both = study("x", {"--no-frame-cache", "--frame-cache", (tmp / "c").string()});
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_FALSE(fs::exists(tmp / "x"));
}

TEST(FrameCacheCli, BadCacheOptionsAreUsageErrors) {
  TempDir tmp;
  write_file(tmp / "a_file", "not a directory");
  RunResult r = run_smoke(tmp, "x", "multi", {"--frame-cache", (tmp / "a_file").string()});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("a_file")) << r.output;
  EXPECT_FALSE(fs::exists(tmp / "x"));
  r = run_smoke(tmp, "x", "multi", {"--frame-cache", (tmp / "c").string(), "--frame-cache-size", "12X"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--frame-cache-size '12X'")) << r.output;
  r = run_smoke(tmp, "x", "multi", {"--frame-cache", (tmp / "c").string(), "--frame-cache-size", "1M"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("at least 64M")) << r.output;
  EXPECT_FALSE(fs::exists(tmp / "x"));
}

}  // namespace
