// `wingman montecarlo` end to end on the smoke scenario: worker processes, aggregate files,
// a failed run that does not sink the others, refusal to mix with earlier runs, and --resume.
// GCC 12 warns falsely about std::string concatenation inlined from gtest (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"

using namespace wingman::app::test;
using ::testing::HasSubstr;

TEST(MonteCarloCli, RunsInWorkersAggregatesAndResumes) {
  TempDir tmp;
  const fs::path out = tmp / "mc";
  // Seed 2's results directory is blocked by a directory that is not ours: that run fails.
  fs::create_directories(out / "runs" / "seed2");
  write_file(out / "runs" / "seed2" / "keep.txt", "not a results directory");
  write_file(out / ".wingman-montecarlo", "");
  RunResult r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "3", "--jobs", "2", "--out",
                             out.string(), "--no-plots", "--variant", "multi"},
                            tmp.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;  // one run failed
  EXPECT_THAT(r.output, HasSubstr("seed 2")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("not a wingman results directory")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("2 runs finished")) << r.output;
  EXPECT_TRUE(fs::exists(out / "runs" / "seed1" / "multi" / "metrics.json"));
  EXPECT_TRUE(fs::exists(out / "runs" / "seed3" / "multi" / "metrics.json"));
  EXPECT_TRUE(fs::exists(out / "runs" / "seed2" / "keep.txt"));  // untouched

  const auto doc = nlohmann::json::parse(read_file(out / "montecarlo.json"));
  EXPECT_EQ(doc["seeds"], nlohmann::json::array({1, 3}));
  ASSERT_EQ(doc["failed_seeds"].size(), 1u);  // the failed run is listed with its reason
  EXPECT_EQ(doc["failed_seeds"][0]["seed"], 2);
  EXPECT_THAT(doc["failed_seeds"][0]["reason"].get<std::string>(), HasSubstr("not a wingman results directory"));
  const auto& mc = doc["variants"];
  ASSERT_EQ(mc.size(), 1u);
  EXPECT_EQ(mc[0]["label"], "multi");
  EXPECT_EQ(mc[0]["runs"], 2);
  EXPECT_EQ(mc[0]["nees_dof"], 18);
  const double lo = mc[0]["nees_bounds"][0], hi = mc[0]["nees_bounds"][1];
  EXPECT_LT(lo, 18);
  EXPECT_GT(hi, 18);
  const auto& total = mc[0]["phases"].back();
  EXPECT_EQ(total["name"], "total");
  EXPECT_GT(total["nees_steps"].get<int>(), 100);
  EXPECT_GE(total["nees_fraction_inside"].get<double>(), 0.0);
  EXPECT_TRUE(fs::exists(out / "nees.csv"));
  EXPECT_FALSE(fs::exists(out / "comparison.json"));  // one variant: nothing to compare

  // Without --resume the finished runs are not mixed in silently.
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "3", "--out", out.string(), "--no-plots"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--resume")) << r.output;

  // With --resume, once the blocker is gone, only seed 2 runs and all three are aggregated.
  fs::remove_all(out / "runs" / "seed2");
  // --batch 2 tests seeds 1-2 as one batch; seed 3 is left out of it.
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "3", "--out", out.string(), "--no-plots",
                   "--variant", "multi", "--resume", "--batch", "2"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("2 of 3 runs already finished")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("batches of 2 runs")) << r.output;
  const auto resumed = nlohmann::json::parse(read_file(out / "montecarlo.json"))["variants"];
  EXPECT_EQ(resumed[0]["runs"], 3);
  ASSERT_EQ(resumed[0]["batch_test"]["batches"].size(), 1u);
  EXPECT_EQ(resumed[0]["batch_test"]["batches"][0]["label"], "seeds 1-2");
}

// With both variants, single-UAV is compared with multi-UAV seed by seed (eval/stats/paired.hpp).
TEST(MonteCarloCli, ComparesTheVariantsSeedBySeed) {
  TempDir tmp;
  const fs::path out = tmp / "mc";
  const RunResult r = run_wingman(
      {"montecarlo", kSmoke.string(), "--runs", "2", "--jobs", "2", "--out", out.string(), "--no-plots"},
      tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("single against multi, paired over 2 seeds")) << r.output;
  const auto c = nlohmann::json::parse(read_file(out / "comparison.json"));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0]["a"], "multi");
  EXPECT_EQ(c[0]["b"], "single");
  // lead, uav1 and the landmarks, x y z each, then lead and uav1 in each of smoke.yaml's 3 phases.
  ASSERT_EQ(c[0]["rows"].size(), 9u + 18u);
  EXPECT_EQ(c[0]["rows"][0]["agent"], "lead");
  EXPECT_EQ(c[0]["rows"][8]["agent"], "landmarks");
  EXPECT_EQ(c[0]["rows"][9]["agent"], "lead");
  EXPECT_NE(c[0]["rows"][9]["phase"], "");
  for (const auto& row : c[0]["rows"]) {
    EXPECT_EQ(row["seeds"], 2);
    EXPECT_GT(row["ratio_b_over_a"].get<double>(), 0.0);
  }
}

TEST(MonteCarloCli, BadInputExits2AndWritesNothing) {
  TempDir tmp;
  const fs::path out = tmp / "mc";
  RunResult r = run_wingman({"montecarlo", (tmp / "missing.yaml").string(), "--runs", "2", "--out",
                             out.string(), "--no-plots"},
                            tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("missing.yaml")) << r.output;
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "0", "--out", out.string(), "--no-plots"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(out));
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "2", "--batch", "3", "--out", out.string(),
                   "--no-plots"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--batch 3")) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // A directory that is not ours is refused.
  fs::create_directories(out);
  write_file(out / "thesis.tex", "");
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "1", "--out", out.string(), "--no-plots"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(out / "runs"));
}
