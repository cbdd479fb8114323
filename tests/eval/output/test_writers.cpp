#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "eval/metrics/metrics.hpp"
#include "eval/output/writers.hpp"
#include "eval/eval_test_support.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> read_lines(const fs::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in.good()) << p;
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string f; std::getline(ss, f, sep);) out.push_back(f);
  if (!s.empty() && s.back() == sep) out.emplace_back();
  return out;
}

TEST(Writers, MetricsJsonHasTablesAndNullForNaN) {
  test::TempDir tmp;
  const RunRecord run = test::make_record();
  const fs::path path = tmp.path() / "metrics.json";
  write_metrics_json(compute_metrics(run), run, path);

  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const char* key : {"software_version", "scenario", "phases", "table4", "table5", "table3",
                          "nees", "timings_ms", "landmarks", "wall_time_s", "steps"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["software_version"], "0.1.0+test");
  EXPECT_EQ(j["scenario"]["name"], "test");
  EXPECT_EQ(j["scenario"]["path"], "scenes/test.yaml");
  EXPECT_EQ(j["scenario"]["variant"], "default");
  EXPECT_EQ(j["scenario"]["seed"], 42);
  EXPECT_EQ(j["scenario"]["estimator_mode"], "multi");
  ASSERT_EQ(j["phases"].size(), 2u);
  EXPECT_EQ(j["phases"][1]["name"], "config2");
  EXPECT_DOUBLE_EQ(j["phases"][1]["t_start"].get<double>(), 10.0);
  EXPECT_EQ(j["phases"][1]["config"], "2");

  const auto& t4 = j["table4"];
  ASSERT_EQ(t4["phases"].size(), 2u);
  EXPECT_EQ(t4["phases"][1]["phase"], 1);
  EXPECT_NEAR(t4["phases"][0]["agents"]["lead"]["mse"][0].get<double>(), 0.25, 1e-12);
  EXPECT_NEAR(t4["phases"][1]["agents"]["uav1"]["mse"][2].get<double>(), 4.0, 1e-12);
  EXPECT_NEAR(t4["phases"][1]["agents"]["uav1"]["max_error"].get<double>(), 2.0, 1e-12);
  EXPECT_NEAR(t4["total"]["uav1"]["mse"][2].get<double>(), 2.2, 1e-12);
  EXPECT_NEAR(t4["total"]["uav1"]["rms_error"].get<double>(), std::sqrt(53.0 / 20.0), 1e-12);

  const auto& t5 = j["table5"];
  ASSERT_EQ(t5["phases"].size(), 2u);
  EXPECT_EQ(t5["phases"][0]["count"], 2);
  EXPECT_NEAR(t5["phases"][0]["init_mse"][0].get<double>(), 5.0, 1e-12);
  EXPECT_EQ(t5["phases"][1]["count"], 0);
  EXPECT_TRUE(t5["phases"][1]["final_mse"][0].is_null());
  EXPECT_TRUE(t5["phases"][1]["init_mse"][2].is_null());
  EXPECT_EQ(t5["total"]["count"], 3);
  EXPECT_NEAR(t5["total"]["final_mse"][2].get<double>(), 1.0 / 3.0, 1e-12);

  ASSERT_EQ(j["table3"].size(), 2u);
  EXPECT_EQ(j["table3"][0]["channel"], "uav1");
  EXPECT_EQ(j["table3"][0]["correspondences"], 1000);
  EXPECT_EQ(j["table3"][0]["outliers_accepted"], 8);
  EXPECT_NEAR(j["table3"][0]["accepted_outlier_fraction"].get<double>(), 0.01, 1e-15);
  EXPECT_TRUE(j["table3"][1]["accepted_outlier_fraction"].is_null());

  EXPECT_EQ(j["nees"]["dof"], 12);
  EXPECT_NEAR(j["nees"]["mean"].get<double>(), 226.0 / 20.0, 1e-12);
  ASSERT_EQ(j["nees"]["per_step"].size(), 22u);
  EXPECT_TRUE(j["nees"]["per_step"][5].is_null());
  EXPECT_DOUBLE_EQ(j["nees"]["per_step"][6].get<double>(), 6.0);
  EXPECT_EQ(j["nees"]["per_phase_mean"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["nees"]["per_agent"]["uav1"]["position_per_phase_mean"][1].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j["nees"]["per_agent"]["uav1"]["velocity_per_phase_mean"][1].get<double>(), 7.5);

  for (const char* t : {"predict", "update", "init", "total"}) {
    for (const char* s : {"mean", "median", "p95", "max"}) {
      EXPECT_TRUE(j["timings_ms"][t].contains(s)) << t << "." << s;
    }
  }
  EXPECT_DOUBLE_EQ(j["timings_ms"]["predict"]["median"].get<double>(), 11.0);
  EXPECT_DOUBLE_EQ(j["timings_ms"]["total"]["max"].get<double>(), 63.0);

  EXPECT_EQ(j["landmarks"]["initialised"], 3);
  EXPECT_EQ(j["landmarks"]["max_in_state"], 3);
  EXPECT_EQ(j["landmarks"]["count_per_step"].size(), 22u);
  EXPECT_DOUBLE_EQ(j["wall_time_s"].get<double>(), 1.5);
  EXPECT_EQ(j["steps"], 22);
}

TEST(Writers, TumTrajectoriesParseBack) {
  test::TempDir tmp;
  RunRecord run = test::make_record();
  run.steps[3].t = 3.123456789;
  run.steps[3].agents[1].p_est = Eigen::Vector3d(-1234.56789012, 1e-7, 98765.4321);
  for (std::size_t k = 0; k < run.steps.size(); ++k)  // a camera turning about a tilted axis
    run.steps[k].agents[1].q_est =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * static_cast<double>(k), Eigen::Vector3d(1, 2, 3).normalized()));
  write_tum_trajectories(run, tmp.path() / "traj");

  const std::regex line_re(
      R"(-?\d+\.\d{9}( \S+){7})");
  for (const std::string& agent : run.agent_names) {
    for (const char* kind : {"est", "gt"}) {
      const fs::path p = tmp.path() / "traj" / (agent + "." + kind + ".tum");
      const std::vector<std::string> lines = read_lines(p);
      ASSERT_EQ(lines.size(), run.steps.size() + 1) << p;
      EXPECT_EQ(lines[0], "# timestamp tx ty tz qx qy qz qw");
      for (std::size_t i = 1; i < lines.size(); ++i) {
        ASSERT_TRUE(std::regex_match(lines[i], line_re)) << lines[i];
      }
    }
  }
  // Parse uav1's estimate back and compare to the record at 9 significant digits.
  const std::vector<std::string> lines = read_lines(tmp.path() / "traj" / "uav1.est.tum");
  for (std::size_t k = 0; k < run.steps.size(); ++k) {
    std::istringstream in(lines[k + 1]);
    double t, x, y, z, qx, qy, qz, qw;
    ASSERT_TRUE(in >> t >> x >> y >> z >> qx >> qy >> qz >> qw);
    const Eigen::Vector3d& p = run.steps[k].agents[1].p_est;
    EXPECT_NEAR(t, run.steps[k].t, 1e-9);
    EXPECT_NEAR(x, p.x(), 1e-8 * std::abs(p.x()) + 1e-12);
    EXPECT_NEAR(y, p.y(), 1e-8 * std::abs(p.y()) + 1e-12);
    EXPECT_NEAR(z, p.z(), 1e-8 * std::abs(p.z()) + 1e-12);
    const Eigen::Quaterniond& q = run.steps[k].agents[1].q_est;  // TUM's order: qx qy qz qw
    EXPECT_NEAR(qx, q.x(), 1e-9);
    EXPECT_NEAR(qy, q.y(), 1e-9);
    EXPECT_NEAR(qz, q.z(), 1e-9);
    EXPECT_NEAR(qw, q.w(), 1e-9);
  }
  EXPECT_EQ(split(lines[4], ' ')[0], "3.123456789");
}

TEST(Writers, StepsCsvHeaderAndValues) {
  test::TempDir tmp;
  const RunRecord run = test::make_record();
  write_steps_csv(run, tmp.path() / "steps.csv");
  const std::vector<std::string> lines = read_lines(tmp.path() / "steps.csv");
  ASSERT_EQ(lines.size(), run.steps.size() + 1);
  const std::vector<std::string> header = split(lines[0], ',');
  ASSERT_EQ(header.size(), 3u + 2u * 17u + 12u);
  EXPECT_EQ(header[0], "k");
  EXPECT_EQ(header[3], "lead_px_true");
  EXPECT_EQ(header[6], "lead_px_est");
  EXPECT_EQ(header[9], "lead_vx_true");
  EXPECT_EQ(header[15], "lead_sx");
  EXPECT_EQ(header[18], "lead_nees_p");
  EXPECT_EQ(header[20], "uav1_px_true");
  EXPECT_EQ(header.back(), "t_match_ms");

  auto col = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  for (std::size_t k = 0; k < run.steps.size(); ++k) {
    const std::vector<std::string> row = split(lines[k + 1], ',');
    ASSERT_EQ(row.size(), header.size()) << lines[k + 1];
    EXPECT_EQ(std::stoi(row[col("k")]), run.steps[k].k);
    EXPECT_EQ(std::stoi(row[col("phase")]), run.steps[k].phase);
    // Shortest round-trip formatting reads back exactly.
    EXPECT_EQ(std::stod(row[col("uav1_pz_est")]), run.steps[k].agents[1].p_est.z());
    EXPECT_EQ(std::stod(row[col("uav1_sz")]), run.steps[k].agents[1].p_sigma.z());
    EXPECT_EQ(std::stod(row[col("t_update_ms")]), run.steps[k].t_ms.update);
    if (k != 5) {
      EXPECT_EQ(std::stod(row[col("uav1_nees_v")]), run.steps[k].agents[1].nees_v);
    }
  }
  EXPECT_EQ(split(lines[6], ',')[col("nees")], "");  // no value: an empty field, never "nan"
  EXPECT_EQ(split(lines[6], ',')[col("uav1_nees_v")], "");
}

// A stage or a count is declared once (run_record.hpp); the files follow it.
TEST(Writers, EveryStageAndCountIsAStepsColumnAndEveryStageATimingsEntry) {
  test::TempDir tmp;
  RunRecord run = test::make_record();
  write_steps_csv(run, tmp.path() / "steps.csv");
  const std::vector<std::string> header = split(read_lines(tmp.path() / "steps.csv")[0], ',');
  auto has = [&](const std::string& c) { return std::find(header.begin(), header.end(), c) != header.end(); };
  int stages = 0, counts = 0;
  StageTimings{}.visit([&](const char* stage, double, bool) {
    ++stages;
    EXPECT_TRUE(has(std::string("t_") + stage + "_ms")) << stage;
  });
  StepCounts{}.visit([&](const char* name, int) {
    ++counts;
    EXPECT_TRUE(has(name)) << name;
  });
  EXPECT_EQ(stages, 6);
  EXPECT_EQ(counts, 4);

  run.frontend.enabled = true;  // rendered mode: every stage in timings_ms
  const fs::path path = tmp.path() / "metrics.json";
  write_metrics_json(compute_metrics(run), run, path);
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  StageTimings{}.visit([&](const char* stage, double, bool) { EXPECT_TRUE(j["timings_ms"].contains(stage)) << stage; });
  EXPECT_TRUE(j["timings_ms"].contains("total"));
}

TEST(Writers, LandmarksCsv) {
  test::TempDir tmp;
  const RunRecord run = test::make_record();
  write_landmarks_csv(run, tmp.path() / "landmarks.csv");
  const std::vector<std::string> lines = read_lines(tmp.path() / "landmarks.csv");
  ASSERT_EQ(lines.size(), 4u);
  const std::vector<std::string> header = split(lines[0], ',');
  ASSERT_EQ(header.size(), 17u);
  const std::vector<std::string> second = split(lines[2], ',');
  ASSERT_EQ(second.size(), 17u);
  EXPECT_EQ(second[0], "2");
  EXPECT_EQ(std::stod(second[4]), 6.0);  // init x = 3 + 3
  EXPECT_EQ(second[14], "0");            // init_phase
  EXPECT_EQ(std::stod(second[15]), 15.0);
  EXPECT_EQ(second[16], "inverse_depth");
  EXPECT_EQ(split(lines[1], ',')[15], "");
}

TEST(Writers, CorrespondencesCsvOnlyWhenRecorded) {
  test::TempDir tmp;
  RunRecord run = test::make_record();
  write_results(compute_metrics(run), run, tmp.path() / "off");
  EXPECT_FALSE(fs::exists(tmp.path() / "off" / "correspondences.csv"));

  run.frontend.record_correspondences = true;
  TrackedCorrespondence a;
  a.k = 3, a.t = 0.3, a.cam = 1, a.landmark = 42, a.uv = {10.25, 20.5}, a.true_uv = {10, 21};
  a.accepted = true;
  TrackedCorrespondence b;  // no truth: an outlier by definition, rejected
  b.k = 4, b.t = 0.4, b.cam = 0, b.landmark = 7, b.uv = {1, 2}, b.outlier = true;
  run.frontend.correspondences = {a, b};
  write_results(compute_metrics(run), run, tmp.path() / "on");
  const std::vector<std::string> lines = read_lines(tmp.path() / "on" / "correspondences.csv");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "k,t,cam,landmark,u,v,true_u,true_v,outlier,accepted");
  const std::vector<std::string> r1 = split(lines[1], ',');
  ASSERT_EQ(r1.size(), 10u);
  EXPECT_EQ(r1[0], "3");
  EXPECT_EQ(r1[2], "1");
  EXPECT_EQ(r1[3], "42");
  EXPECT_EQ(std::stod(r1[4]), 10.25);
  EXPECT_EQ(std::stod(r1[7]), 21.0);
  EXPECT_EQ(r1[8], "0");
  EXPECT_EQ(r1[9], "1");
  const std::vector<std::string> r2 = split(lines[2], ',');
  ASSERT_EQ(r2.size(), 10u);
  EXPECT_EQ(r2[6], "");
  EXPECT_EQ(r2[7], "");
  EXPECT_EQ(r2[8], "1");
  EXPECT_EQ(r2[9], "0");
}

TEST(Writers, PlyVertexCountMatchesLandmarksStillInMap) {
  test::TempDir tmp;
  const RunRecord run = test::make_record();
  for (MapPoints which : {MapPoints::estimate, MapPoints::truth}) {
    const fs::path p = tmp.path() / (which == MapPoints::truth ? "map_truth.ply" : "map.ply");
    write_map_ply(run, p, which);
    const std::vector<std::string> lines = read_lines(p);
    ASSERT_GE(lines.size(), 3u);
    EXPECT_EQ(lines[0], "ply");
    EXPECT_EQ(lines[1], "format ascii 1.0");
    int declared = -1;
    std::size_t end = 0;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].rfind("element vertex ", 0) == 0) declared = std::stoi(lines[i].substr(15));
      if (lines[i] == "end_header") end = i;
    }
    ASSERT_GT(end, 0u);
    EXPECT_EQ(declared, 2);  // landmark 2 was removed
    ASSERT_EQ(lines.size() - end - 1, 2u);
    std::istringstream v(lines[end + 1]);
    double x, y, z;
    int r, g, b;
    ASSERT_TRUE(v >> x >> y >> z >> r >> g >> b);
    EXPECT_NEAR(x, which == MapPoints::truth ? 1.0 : 1.1, 1e-6);
    EXPECT_NEAR(y, 2.0, 1e-6);
    if (which == MapPoints::estimate) {
      EXPECT_EQ(b, 180);  // cooperative is blue
    }
  }
}

TEST(Writers, WriteResultsWritesEveryFile) {
  test::TempDir tmp;
  const RunRecord run = test::make_record();
  write_results(compute_metrics(run), run, tmp.path() / "res");
  for (const char* f : {"metrics.json", "steps.csv", "landmarks.csv", "map.ply",
                        "map_truth.ply", "traj/lead.est.tum", "traj/lead.gt.tum",
                        "traj/uav1.est.tum", "traj/uav1.gt.tum"}) {
    EXPECT_TRUE(fs::is_regular_file(tmp.path() / "res" / f)) << f;
  }
}

TEST(Writers, SummaryShowsTables) {
  const RunRecord run = test::make_record();
  const std::string s = format_summary(compute_metrics(run), run);
  EXPECT_NE(s.find("Table 4"), std::string::npos);
  EXPECT_NE(s.find("Table 5"), std::string::npos);
  EXPECT_NE(s.find("Table 3"), std::string::npos);
  EXPECT_NE(s.find("uav1 X"), std::string::npos);
  EXPECT_NE(s.find("config2"), std::string::npos);
  EXPECT_NE(s.find("0.2500"), std::string::npos);  // lead X MSE
  EXPECT_NE(s.find("2.2000"), std::string::npos);  // uav1 Z MSE, total
  EXPECT_NE(s.find("NEES mean 11.300 (dof 12)"), std::string::npos) << s;
  EXPECT_NE(s.find("3 initialised"), std::string::npos);
}

}  // namespace
}  // namespace wingman::eval
