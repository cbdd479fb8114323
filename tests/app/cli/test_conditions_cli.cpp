// Conditions in `wingman pairs`, `wingman score-matches` and `wingman bench-frontend`: a tiny
// flight rendered twice, through the ideal camera and through a rolling shutter (4 px of shear
// across the frame), is benchmarked with the rolling frames and the ideal frames themselves as
// conditions; scores come per condition, the identical condition's same-instant pairs score at
// least the reference's temporal ones, and a condition imaged from other poses, an unknown
// condition in pairs.csv or a missing condition keypoint file end in exit 2 with nothing written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"
#include "app/cli/rendered_suite.hpp"

namespace wingman::app::test {
namespace {

using ::testing::HasSubstr;

std::string uavs(const std::string& camera_extra, const std::string& indent) {
  const std::string cam = "camera: {fx: 40.02, fy: 40.02, cx: 99.5, cy: 99.5, width: 200, height: 200" + camera_extra + "}";
  return indent + "- {name: uav1, initial_position: [-1.5, 0, 15], sees_lead: true, altimeter: true, range: true,\n" +
         indent + "   " + cam + "}\n" + indent + "- {name: uav2, initial_position: [1.5, 0, 17], range: false,\n" +
         indent + "   " + cam + "}\n";
}

// Six frames at 10 Hz of two UAVs over a truck driving at 20 m/s (53 px/s at 15 m).
std::string scenario() {
  return "name: conditions\nrate: 10\nduration: 0.5\nmeasurements: rendered\n"
         "lead: {trajectory: {type: line, velocity: [20, 0, 0]}}\nuavs:\n" +
         uavs("", "  ") + "variants:\n  - name: ideal\n  - name: rolling\n    uavs:\n" +
         uavs(", shutter: {type: rolling, line_delay: 4.0e-4, rows_per_band: 4}", "      ");
}

class ConditionsCli : public RenderedSuite<ConditionsCli> {
 public:
  static std::string render(const fs::path& dir) {
    write_file(dir / "cond.yaml", scenario());
    const RunResult r = run_wingman({"render", (dir / "cond.yaml").string(), "--variant", "ideal", "--variant",
                                     "rolling", "--quiet", "--out", (dir / "ds").string()},
                                    dir);
    return r.exit_code == 0 ? "" : r.output;
  }

 protected:
  static std::string ideal() { return (tmp() / "ds" / "ideal").string(); }
  static std::string rolling() { return "rolling=" + (tmp() / "ds" / "rolling").string(); }
  static std::string same() { return "same=" + ideal(); }  // the reference's own frames: identical imaging
};

// scores.csv's rows as maps from column name to value.
std::vector<std::map<std::string, std::string>> csv_rows(const fs::path& file) {
  std::vector<std::map<std::string, std::string>> rows;
  const auto lines = lines_of(read_file(file));
  auto fields = [](const std::string& line) {
    std::vector<std::string> f;
    std::stringstream in(line);
    for (std::string x; std::getline(in, x, ',');) f.push_back(x);
    return f;
  };
  const auto header = fields(lines.at(0));
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto f = fields(lines[i]);
    std::map<std::string, std::string> row;
    for (std::size_t k = 0; k < header.size() && k < f.size(); ++k) row[header[k]] = f[k];
    rows.push_back(row);
  }
  return rows;
}

// A row's figure (condition, type, all baselines).
double figure(const std::vector<std::map<std::string, std::string>>& rows, const std::string& condition,
              const std::string& type, const std::string& column) {
  for (const auto& r : rows)
    if (r.at("condition") == condition && r.at("type") == type && r.at("baseline") == "all") return std::stod(r.at(column));
  ADD_FAILURE() << "no row " << condition << " " << type;
  return NAN;
}

TEST_F(ConditionsCli, PairsListTheReferencesPairsThenEachConditionsWithSameInstantPairs) {
  const RunResult r = run_wingman({"pairs", ideal(), "--gap", "1", "--gap", "5", "--condition", rolling()}, tmp());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto lines = lines_of(r.output);
  // From frame 0: the reference's 2 UAVs x 2 gaps + 1 cross; rolling's 2 same-instant, 4 temporal, 1 cross.
  ASSERT_EQ(lines.size(), 1u + 5u + 7u) << r.output;
  EXPECT_EQ(lines[0], "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition");
  EXPECT_THAT(lines[1], ::testing::EndsWith(",reference"));
  EXPECT_EQ(lines[6], "5,uav1,0,uav1,0,same-instant,0.0000,rolling");
  EXPECT_THAT(lines[7], ::testing::StartsWith("6,uav1,0,uav1,100000000,temporal,"));
  EXPECT_THAT(lines[12], ::testing::StartsWith("11,uav1,0,uav2,0,cross,"));
}

TEST_F(ConditionsCli, BenchFrontendScoresEveryConditionAndScoreMatchesAgrees) {
  const fs::path out = tmp() / "bench";
  fs::remove_all(out);
  const bool plots = std::system("gnuplot -e 'set terminal pngcairo' > /dev/null 2>&1") == 0;
  std::vector<std::string> args{"bench-frontend", ideal(), "--detector", "orb", "--gap", "1", "--gap", "5",
                                "--condition", rolling(), "--condition", same(), "--out", out.string(), "-q"};
  if (!plots) args.push_back("--no-plots");
  const RunResult r = run_wingman(args, tmp());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("19 pairs (12 temporal, 3 cross-UAV, 4 same-instant) over 2 conditions"));
  EXPECT_THAT(r.output, ::testing::ContainsRegex("\norb +rolling +same-instant +all +2 "));
  const auto rows = csv_rows(out / "scores.csv");
  // The reference's frames as their own condition: the same image at the same instant.
  const double reference_temporal = figure(rows, "reference", "temporal", "precision_3px");
  EXPECT_GT(reference_temporal, 0.6);
  EXPECT_GE(figure(rows, "same", "same-instant", "precision_3px"), reference_temporal);
  EXPECT_GT(figure(rows, "same", "same-instant", "precision_1px"), 0.99);
  EXPECT_GT(figure(rows, "same", "same-instant", "repeatability_1px"), 0.99);
  // Through the rolling shutter the truth follows each row: the matches stay within a few px.
  EXPECT_GT(figure(rows, "rolling", "same-instant", "precision_3px"), 0.8);
  EXPECT_GT(figure(rows, "rolling", "same-instant", "repeatability_3px"), 0.6);
  EXPECT_TRUE(fs::exists(out / "frontends" / "orb" / "conditions" / "rolling" / "keypoints" / "uav2" / "0.csv"));
  EXPECT_TRUE(fs::exists(out / "conditions.csv"));
  if (plots) {
    EXPECT_GT(fs::file_size(out / "plots" / "conditions.png"), 1000u);
  }
  const auto j = nlohmann::json::parse(read_file(out / "scores.json"));
  ASSERT_EQ(j.at("conditions").size(), 2u);
  EXPECT_EQ(j.at("conditions").at(0).at("name"), "rolling");
  EXPECT_EQ(j.at("same_instant_pairs"), 4);

  const fs::path rescored = tmp() / "rescored";
  fs::remove_all(rescored);
  const RunResult s = run_wingman({"score-matches", ideal(), (out / "frontends" / "orb").string(), "--gap", "1", "--gap",
                                   "5", "--condition", rolling(), "--condition", same(), "--out", rescored.string(),
                                   "--no-plots", "-q"},
                                  tmp());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto k = nlohmann::json::parse(read_file(rescored / "scores.json"));
  EXPECT_EQ(k.at("methods").at(0).at("groups"), j.at("methods").at(0).at("groups"));

  // A condition's keypoints file missing, or an unknown condition in pairs.csv: exit 2, named.
  const fs::path sub = out / "frontends" / "orb";
  const fs::path kp = sub / "conditions" / "rolling" / "keypoints" / "uav1" / "100000000.csv";
  const std::string saved = read_file(kp);
  fs::remove(kp);
  fs::remove_all(rescored);
  const RunResult missing = run_wingman({"score-matches", ideal(), sub.string(), "--gap", "1", "--gap", "5",
                                         "--condition", rolling(), "--condition", same(), "--out",
                                         rescored.string(), "--no-plots", "-q"},
                                        tmp());
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr(kp.string() + ": missing"));
  EXPECT_FALSE(fs::exists(rescored));
  write_file(kp, saved);
  write_file(tmp() / "fog.csv", "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition\n"
                                "0,uav1,0,uav1,0,same-instant,0,rolling\n1,uav1,0,uav1,0,same-instant,0,fog\n");
  const RunResult fog = run_wingman({"score-matches", ideal(), sub.string(), "--pairs", (tmp() / "fog.csv").string(),
                                     "--condition", rolling(), "--out", rescored.string(), "--no-plots", "-q"},
                                    tmp());
  EXPECT_EQ(fog.exit_code, 2) << fog.output;
  EXPECT_THAT(fog.output, HasSubstr("fog.csv:3: condition 'fog' is none of the datasets given (reference, rolling;"));
  EXPECT_FALSE(fs::exists(rescored));
}

TEST_F(ConditionsCli, AConditionImagedFromOtherPosesExitsTwoWithNothingWritten) {
  const fs::path moved = tmp() / "moved";
  fs::remove_all(moved);
  fs::copy(tmp() / "ds" / "rolling", moved, fs::copy_options::recursive);
  const fs::path poses = moved / "uav2" / "mav0" / "cam0_pose0" / "data.csv";
  auto lines = lines_of(read_file(poses));
  ASSERT_GE(lines.size(), 3u);
  const auto comma = lines[2].find(',');
  lines[2] = lines[2].substr(0, comma + 1) + "1" + lines[2].substr(comma + 1);  // x: 1 m or more off
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  write_file(poses, text);
  const fs::path out = tmp() / "moved_bench";
  fs::remove_all(out);
  const std::string condition = "moved=" + moved.string();
  const RunResult r = run_wingman({"bench-frontend", ideal(), "--detector", "orb", "--condition", condition, "--out",
                                   out.string(), "--no-plots", "-q"},
                                  tmp());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(poses.string() + ":3: condition moved does not image the reference " + ideal() +
                                  ": the true camera pose at t_ns 100000000 differs from the reference's by"));
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(tmp()))
    EXPECT_EQ(e.path().filename().string().find("moved_bench.partial"), std::string::npos) << e.path();
  const RunResult p = run_wingman({"pairs", ideal(), "--condition", condition, "--out", (tmp() / "p.csv").string()}, tmp());
  EXPECT_EQ(p.exit_code, 2) << p.output;
  EXPECT_FALSE(fs::exists(tmp() / "p.csv"));
  const RunResult bad = run_wingman({"pairs", ideal(), "--condition", "moved"}, tmp());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr("--condition moved: expected NAME=DIR"));
}

}  // namespace
}  // namespace wingman::app::test
