// `wingman pairs`, `wingman score-matches` and `wingman bench-frontend` on a small rendered
// dataset (scenes/rendered_smoke.yaml, 11 frames): a hand-made matches directory with known
// correct and wrong matches scores exactly; the built-in detectors are written in the same file
// format and score the same through score-matches; bad submissions end in exit 2 naming the
// file and line, with nothing written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <algorithm>

#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"
#include "app/cli/rendered_suite.hpp"
#include "datasets/dataset.hpp"
#include "frontend_bench/correspondence.hpp"
#include "frontend_bench/match_files.hpp"

namespace wingman::app::test {
namespace {

using ::testing::HasSubstr;

class ScoreMatchesCli : public RenderedSuite<ScoreMatchesCli> {
 public:
  // One dataset for the suite: rendering is the slow part.
  static std::string render(const fs::path& dir) {
    const RunResult r = run_wingman({"render", "scenes/rendered_smoke.yaml", "--variant", "multi", "--frames", "11",
                                     "--quiet", "--out", (dir / "ds").string()},
                                    dir);
    return r.exit_code == 0 ? "" : r.output;
  }

 protected:
  static fs::path ds() { return tmp() / "ds"; }
};

const char* kPairsHeader = "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m\n";  // the reference-only columns

// Two pairs: uav1 at 0 s and 0.5 s (temporal), uav1 and uav2 at 0 s (cross).
std::string two_pairs() {
  return std::string(kPairsHeader) + "0,uav1,0,uav1,500000000,temporal,0\n1,uav1,0,uav2,0,cross,0\n";
}

std::string keypoints_csv(const std::vector<Eigen::Vector2d>& uvs) {
  std::string s = "x,y\n";
  for (const auto& uv : uvs) s += fmt::format("{},{}\n", uv.x(), uv.y());
  return s;
}

// Two pairs sharing frame A (uav1 at 0 s): B = uav1 at 0.5 s and uav2 at 0 s. A's keypoints
// a0..a5, 100 px apart, are seen in both Bs. In each B: b0 at a0's truth, b1 0.5 px and b2 2 px
// off a1's and a2's, b3 30 px off a3's, b4 at a4's truth, none near a5's. Matches (0,0) (1,1)
// (2,2) (3,3) (5,0): correct at 1 px 2 of 5, at 3 and 5 px 3 of 5; a4 is left unmatched.
fs::path known_submission(const fs::path& ds_dir, const fs::path& tmp, const std::string& name) {
  const datasets::Dataset ds = datasets::read_dataset(ds_dir);
  const frontend_bench::FrameTruth a = frontend_bench::frame_truth(ds, "uav1", 0);
  const std::vector<std::pair<std::string, std::int64_t>> bs{{"uav1", 500000000}, {"uav2", 0}};
  std::vector<frontend_bench::FrameTruth> b;
  for (const auto& [agent, t] : bs) b.push_back(frontend_bench::frame_truth(ds, agent, t));
  auto seen_in = [&](const Eigen::Vector2d& uv) {
    int n = 0;
    for (const auto& fb : b) n += frontend_bench::true_correspondence(a, fb, uv).found();
    return n;
  };
  std::vector<Eigen::Vector2d> kp_a;
  for (int y = 300; y <= 700 && kp_a.size() < 6; y += 100)
    for (int x = 300; x <= 700 && kp_a.size() < 6; x += 100)
      if (seen_in({x, y}) == 2) kp_a.emplace_back(x, y);
  EXPECT_EQ(kp_a.size(), 6u);
  const fs::path sub = tmp / name;
  fs::remove_all(sub);
  for (const auto& agent : {"uav1", "uav2"}) fs::create_directories(sub / "keypoints" / agent);
  fs::create_directories(sub / "matches");
  write_file(frontend_bench::keypoints_file(sub, "uav1", 0), keypoints_csv(kp_a));
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::vector<Eigen::Vector2d> truth;
    for (std::size_t k = 0; k < 5; ++k) truth.push_back(frontend_bench::true_correspondence(a, b[i], kp_a[k]).uv_b);
    const std::vector<Eigen::Vector2d> kp_b{truth[0], truth[1] + Eigen::Vector2d(0.5, 0),
                                            truth[2] + Eigen::Vector2d(0, 2),
                                            truth[3] + Eigen::Vector2d(0, 30), truth[4]};
    write_file(frontend_bench::keypoints_file(sub, bs[i].first, bs[i].second), keypoints_csv(kp_b));
    write_file(frontend_bench::matches_file(sub, static_cast<int>(i)), "index_a,index_b\n0,0\n1,1\n2,2\n3,3\n5,0\n");
  }
  write_file(tmp / "pairs.csv", two_pairs());
  return sub;
}

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(read_file(p)); }

// score-matches of the submission `sub` on pairs.csv into a fresh `out`.
RunResult score_into(const fs::path& ds_dir, const fs::path& tmp, const fs::path& sub, const fs::path& out) {
  fs::remove_all(out);
  return run_wingman({"score-matches", ds_dir.string(), sub.string(), "--pairs", (tmp / "pairs.csv").string(),
                      "--out", out.string(), "--no-plots", "-q"},
                     tmp);
}

// A group's figure at a threshold of scores.json.
double at(const nlohmann::json& group, std::size_t threshold, const char* what) {
  return group.at("thresholds").at(threshold).at(what).get<double>();
}

TEST_F(ScoreMatchesCli, PairsListsTemporalAndCrossPairsWithBaselines) {
  const RunResult r = run_wingman({"pairs", ds().string()}, tmp());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto lines = lines_of(r.output);
  // 11 frames, stride 10, gaps 1, 5, 10: per UAV three temporal pairs from frame 0; cross pairs at
  // frames 0 and 10.
  ASSERT_EQ(lines.size(), 9u) << r.output;
  EXPECT_EQ(lines[0], "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition");
  EXPECT_THAT(lines[1], ::testing::StartsWith("0,uav1,0,uav1,100000000,temporal,"));
  EXPECT_THAT(lines[7], ::testing::StartsWith("6,uav1,0,uav2,0,cross,"));
  EXPECT_THAT(lines[8], ::testing::StartsWith("7,uav1,1000000000,uav2,1000000000,cross,"));
  // The UAVs fly 3 m apart horizontally and 2 m vertically at the start.
  EXPECT_THAT(lines[7], ::testing::EndsWith(",reference"));
  const std::string before_condition = lines[7].substr(0, lines[7].rfind(','));
  const double baseline = std::stod(before_condition.substr(before_condition.rfind(',') + 1));
  EXPECT_NEAR(baseline, std::sqrt(3.0 * 3.0 + 2.0 * 2.0), 0.3);
}

TEST_F(ScoreMatchesCli, HandMadeMatchesScoreExactPrecisionAndRecall) {
  const fs::path sub = known_submission(ds(), tmp(), "known");
  const fs::path out = tmp() / "known_scores";
  const RunResult r = score_into(ds(), tmp(), sub, out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("known"));
  const auto j = read_json(out / "scores.json");
  EXPECT_EQ(j.at("pairs"), 2);
  const auto& groups = j.at("methods").at(0).at("groups");
  ASSERT_GE(groups.size(), 3u);
  for (const auto& g : groups) {  // each pair alone, and both pooled, score the same ratios
    SCOPED_TRACE(g.at("type").get<std::string>() + " " + g.at("baseline").get<std::string>());
    const long n = g.at("pairs").get<long>();
    EXPECT_EQ(g.at("matches").get<long>(), 5 * n);
    EXPECT_EQ(g.at("covisible").get<long>(), 6 * n);
    // thresholds 1..10 px: index 0 is 1 px, 2 is 3 px, 4 is 5 px
    EXPECT_DOUBLE_EQ(at(g, 0, "precision"), 0.4);
    EXPECT_DOUBLE_EQ(at(g, 2, "precision"), 0.6);
    EXPECT_DOUBLE_EQ(at(g, 4, "precision"), 0.6);
    EXPECT_DOUBLE_EQ(at(g, 0, "recall"), 2.0 / 3.0);
    EXPECT_DOUBLE_EQ(at(g, 2, "recall"), 0.75);
    EXPECT_DOUBLE_EQ(at(g, 0, "repeatability"), 0.5);        // a0, a1, a4 of 6
    EXPECT_DOUBLE_EQ(at(g, 2, "repeatability"), 4.0 / 6.0);  // and a2
    EXPECT_NEAR(g.at("localisation_px").get<double>(), 2.5 / 3.0, 1e-6);
  }
  EXPECT_TRUE(fs::exists(out / "scores.csv"));
  EXPECT_TRUE(fs::exists(out / "curves.csv"));
  // The table: the 'all' row at 1, 3 and 5 px.
  EXPECT_THAT(r.output, ::testing::ContainsRegex("known +all +all +2 .* 40.0 +60.0 +60.0 +66.7 +75.0 +75.0 +0.83"));
  // An existing output is not replaced without --force.
  const RunResult again = run_wingman({"score-matches", ds().string(), sub.string(), "--pairs",
                                       (tmp() / "pairs.csv").string(), "--out", out.string(), "--no-plots", "-q"},
                                      tmp());
  EXPECT_EQ(again.exit_code, 2) << again.output;
  EXPECT_THAT(again.output, HasSubstr("--force"));
}

// Runs score-matches on a submission damaged by `damage` and expects exit 2 with `message`,
// and no output directory.
void expect_refused(const fs::path& ds, const fs::path& tmp, const std::function<void(const fs::path&)>& damage,
                    const std::string& message) {
  const fs::path sub = known_submission(ds, tmp, "damaged");
  damage(sub);
  const fs::path out = tmp / "damaged_scores";
  fs::remove_all(out);
  const RunResult r = run_wingman({"score-matches", ds.string(), sub.string(), "--pairs",
                                   (tmp / "pairs.csv").string(), "--out", out.string(), "--no-plots", "-q"},
                                  tmp);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(message));
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(tmp))
    EXPECT_EQ(e.path().filename().string().find("damaged_scores.partial"), std::string::npos) << e.path();
}

TEST_F(ScoreMatchesCli, MalformedMatchRowIsNamedWithFileAndLine) {
  expect_refused(ds(), tmp(), [](const fs::path& sub) {
    write_file(sub / "matches" / "1.csv", "index_a,index_b\n0,0\n1;1\n");
  }, "matches/1.csv:3: expected 2 fields, got 1");
}

TEST_F(ScoreMatchesCli, MatchIndexOutOfRangeIsNamedWithFileAndLine) {
  expect_refused(ds(), tmp(), [](const fs::path& sub) {
    write_file(sub / "matches" / "0.csv", "index_a,index_b\n0,0\n1,5\n");
  }, "matches/0.csv:3: index_b 5 out of range: frame B has 5 keypoints");
}

TEST_F(ScoreMatchesCli, MissingMatchesFileOfAListedPairIsNamed) {
  expect_refused(ds(), tmp(), [](const fs::path& sub) { fs::remove(sub / "matches" / "1.csv"); },
                 "matches/1.csv: missing");
}

TEST_F(ScoreMatchesCli, MalformedKeypointRowIsNamedWithFileAndLine) {
  expect_refused(ds(), tmp(), [](const fs::path& sub) {
    write_file(sub / "keypoints" / "uav2" / "0.csv", "x,y\n10,20\n10,\n");
  }, "keypoints/uav2/0.csv:3: y '' is not a number");
}

TEST_F(ScoreMatchesCli, PairNamingAFrameTheDatasetLacksIsNamedWithFileAndLine) {
  expect_refused(ds(), tmp(), [&](const fs::path&) {
    write_file(tmp() / "pairs.csv", std::string(kPairsHeader) + "0,uav1,0,uav1,500000000,temporal,0\n"
                                                               "1,uav1,0,uav3,0,cross,0\n");
  }, "pairs.csv:3: names a frame the dataset");
}

// The built-in detectors through the benchmark's files: bench-frontend writes each one's
// keypoints and matches, scores them, and score-matches on those files gives the same numbers.
TEST_F(ScoreMatchesCli, BenchFrontendScoresBuiltInDetectorsThroughTheFileFormat) {
  const fs::path out = tmp() / "bench";
  fs::remove_all(out);
  const RunResult r = run_wingman({"bench-frontend", ds().string(), "--out", out.string(), "--no-plots", "-q"}, tmp());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = read_json(out / "scores.json");
  ASSERT_EQ(j.at("methods").size(), 4u);
  for (const auto& m : j.at("methods")) {
    const std::string name = m.at("name");
    SCOPED_TRACE(name);
    EXPECT_TRUE(fs::exists(out / "frontends" / name / "keypoints" / "uav2" / "1000000000.csv"));
    EXPECT_TRUE(fs::exists(out / "frontends" / name / "matches" / "7.csv"));
    EXPECT_GT(m.at("detect_ms_per_frame").get<double>(), 0);
    EXPECT_GT(m.at("keypoints_per_frame").get<double>(), 300);
    const auto& all = m.at("groups").at(0);
    EXPECT_EQ(all.at("pairs"), 8);
    EXPECT_GT(all.at("matches").get<long>(), 8 * 50);
    // Rendered frames 0.1-1 s apart and 3.6 m across: most matches of every detector are right.
    EXPECT_GT(at(all, 2, "precision"), 0.8);
    EXPECT_GT(at(all, 2, "recall"), 0.1);
    EXPECT_GT(at(all, 2, "repeatability"), 0.2);
    EXPECT_LT(all.at("localisation_px").get<double>(), 1.5);
  }
  EXPECT_THAT(r.output, ::testing::ContainsRegex("\nsift +all +all +8 "));

  const fs::path rescored = tmp() / "rescored";
  fs::remove_all(rescored);
  const RunResult s = run_wingman({"score-matches", ds().string(), (out / "frontends" / "akaze").string(),
                                   "--out", rescored.string(), "--no-plots", "-q"}, tmp());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto k = read_json(rescored / "scores.json");
  const auto& bench_akaze = j.at("methods").at(2);
  ASSERT_EQ(bench_akaze.at("name"), "akaze");
  EXPECT_EQ(k.at("methods").at(0).at("name"), "akaze");
  EXPECT_EQ(k.at("methods").at(0).at("groups"), bench_akaze.at("groups"));
}

// --frames means the same on pairs, bench-frontend and score-matches: the same pairs, said when
// some are left out, and recorded in scores.json with the matcher's options where there is one.
TEST_F(ScoreMatchesCli, TheSameLimitKeepsTheSamePairsOnEveryCommand) {
  // Frames 0..5 of 11: per UAV the temporal pairs (0, 1) and (0, 5), and the cross pair at 0.
  const RunResult pairs = run_wingman({"pairs", ds().string(), "--frames", "6"}, tmp());
  ASSERT_EQ(pairs.exit_code, 0) << pairs.output;
  EXPECT_THAT(pairs.output, HasSubstr("pairs: 5 of 8 within --duration/--frames; the 3 past it are left out"));
  EXPECT_EQ(std::count(pairs.output.begin(), pairs.output.end(), '\n'), 1 + 5 + 1) << pairs.output;

  const fs::path bench = tmp() / "bench_limited";
  fs::remove_all(bench);
  const RunResult b = run_wingman({"bench-frontend", ds().string(), "--detector", "orb", "--frames", "6",
                                   "--ratio", "0.7", "--no-mutual", "--out", bench.string(), "--no-plots"},
                                  tmp());
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_THAT(b.output, HasSubstr("pairs: 5 of 8 within --duration/--frames"));
  const auto j = read_json(bench / "scores.json");
  EXPECT_EQ(j.at("pairs"), 5);
  EXPECT_EQ(j.at("limit").at("frames"), 6);
  EXPECT_DOUBLE_EQ(j.at("matcher").at("ratio").get<double>(), 0.7);
  EXPECT_EQ(j.at("matcher").at("mutual"), false);
  EXPECT_GT(j.at("matcher").at("max_features").get<int>(), 0);

  const fs::path rescored = tmp() / "rescored_limited";
  fs::remove_all(rescored);
  const RunResult s = run_wingman({"score-matches", ds().string(), (bench / "frontends" / "orb").string(),
                                   "--frames", "6", "--out", rescored.string(), "--no-plots", "-q"},
                                  tmp());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto k = read_json(rescored / "scores.json");
  EXPECT_EQ(k.at("pairs"), 5);
  EXPECT_EQ(k.at("limit").at("frames"), 6);
  EXPECT_TRUE(k.at("matcher").is_null());  // a frontend's own matches: the benchmark did not make them
  EXPECT_EQ(k.at("methods").at(0).at("groups"), j.at("methods").at(0).at("groups"));
}

// A frontend's timings.csv gives it the ms-per-frame figure the built-in detectors get.
TEST_F(ScoreMatchesCli, AFrontendsTimingsFileGivesItsMsPerFrame) {
  const fs::path sub = known_submission(ds(), tmp(), "timed");
  write_file(sub / "timings.csv", "agent,t_ns,ms\nuav1,0,10\nuav1,500000000,20\nuav2,0,30\nuav2,100000000,99\n");
  const fs::path out = tmp() / "timed_scores";
  const RunResult r = score_into(ds(), tmp(), sub, out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The three frames the two pairs use: (10 + 20 + 30) / 3.
  EXPECT_DOUBLE_EQ(read_json(out / "scores.json").at("methods").at(0).at("detect_ms_per_frame").get<double>(), 20.0);

  write_file(sub / "timings.csv", "agent,t_ns,ms\nuav1,0,10\n");
  const RunResult missing = score_into(ds(), tmp(), sub, out);
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("timings.csv: no time for frame"));
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(ScoreMatchesCli, HelpShowsFlagsWithoutAnInternalDefault) {
  const RunResult r = run_wingman({"bench-frontend", "--help"}, tmp());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--no-mutual"));
  EXPECT_THAT(r.output, ::testing::Not(HasSubstr("{false}")));
  for (const char* cmd : {"pairs", "score-matches", "bench-frontend"})
    EXPECT_THAT(run_wingman({cmd, "--help"}, tmp()).output, HasSubstr("--frames")) << cmd;
}

TEST_F(ScoreMatchesCli, BenchFrontendWritesThePlotWhenGnuplotIsPresent) {
  if (std::system("gnuplot -e 'set terminal pngcairo' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no gnuplot";
  const fs::path out = tmp() / "bench_plot";
  fs::remove_all(out);
  const RunResult r = run_wingman({"bench-frontend", ds().string(), "--detector", "orb", "--gap", "1",
                                   "--no-cross", "--out", out.string(), "-q"}, tmp());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GT(fs::file_size(out / "plots" / "match_curves.png"), 1000u);
  EXPECT_TRUE(fs::exists(out / "plots" / "match_curves.gp"));
  EXPECT_EQ(read_json(out / "scores.json").at("pairs"), 2);  // frame 0 and frame 10, gap 1: frame 10 has no successor
}

}  // namespace
}  // namespace wingman::app::test
