// The `wingman` command line, run as a real process: exit codes, error messages that name the
// file, line and key, the results directory it leaves (or does not leave), reproducibility.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "app/app_test_support.hpp"

namespace wingman::app::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Names of the entries of a directory that look like a staging directory ("*.partial-*").
std::vector<std::string> partial_entries(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.find(".partial-") != std::string::npos) out.push_back(name);
  }
  return out;
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::is_regular_file(kBinary)) << "wingman not built at " << kBinary;
    ASSERT_TRUE(fs::is_regular_file(kSmoke)) << kSmoke;
  }
  // The output directory for a run, inside a directory of its own so that siblings can be listed.
  fs::path out_dir(const std::string& name = "out") const { return tmp_ / name; }
  // A copy of smoke.yaml, patched by `edit`, written into the temp directory.
  template <class Edit>
  fs::path patched_smoke(const std::string& file_name, Edit edit) const {
    std::string text = read_file(kSmoke);
    edit(text);
    const fs::path p = tmp_ / file_name;
    write_file(p, text);
    return p;
  }
  // Expects a run that failed on the scenario: exit 2, `file:line:` and the key path in the
  // message, no results directory and no staging directory left behind.
  void expect_scenario_error(const fs::path& scn, int line, const std::string& key_path) {
    const fs::path out = out_dir();
    const RunResult r = run_wingman({"run", scn.string(), "--out", out.string(), "--no-plots", "-q"},
                                    tmp_.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(scn.string() + ":" + std::to_string(line) + ":")) << r.output;
    EXPECT_THAT(r.output, HasSubstr(key_path)) << r.output;
    EXPECT_FALSE(fs::exists(out)) << "results directory created for a bad scenario";
    EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());
  }

  TempDir tmp_;
};

TEST_F(CliTest, MisspelledKeyExits2WithFileLineAndKeyPath) {
  int line = -1;
  const fs::path scn = patched_smoke("typo.yaml", [&](std::string& text) {
    const auto gating = text.find("gating:");
    ASSERT_NE(gating, std::string::npos);
    line = replace_once(text, "probability:", "probabilty:", gating);
  });
  ASSERT_GT(line, 0);
  expect_scenario_error(scn, line, "estimator.gating.probabilty");
}

TEST_F(CliTest, MisspelledKeyMessageIsOneLineOnStderr) {
  // The message goes to stderr: with stdout discarded it is still there.
  const fs::path scn = patched_smoke("typo.yaml", [&](std::string& text) {
    replace_once(text, "probability:", "probabilty:", text.find("gating:"));
  });
  const fs::path log = tmp_ / "stderr.txt";
  const std::string cmd = quote(kBinary.string()) + " run " + quote(scn.string()) + " --out " +
                          quote(out_dir().string()) + " --no-plots -q > /dev/null 2> " +
                          quote(log.string());
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  const std::string err = read_file(log);
  EXPECT_THAT(err, HasSubstr("probabilty"));
  EXPECT_EQ(lines_of(err).size(), 1u) << err;
}

TEST_F(CliTest, WrongTypeExits2NamingTheKey) {
  int line = -1;
  const fs::path scn = patched_smoke("wrong_type.yaml", [&](std::string& text) {
    line = replace_top_level_value(text, "duration", "abc");
  });
  ASSERT_GT(line, 0);
  expect_scenario_error(scn, line, "duration");
}

TEST_F(CliTest, OutOfRangeValueExits2NamingTheKey) {
  int line = -1;
  const fs::path scn = patched_smoke("bad_rate.yaml", [&](std::string& text) {
    line = replace_top_level_value(text, "rate", "-1");
  });
  ASSERT_GT(line, 0);
  expect_scenario_error(scn, line, "rate");
}

TEST_F(CliTest, NestedOutOfRangeValueNamesTheFullKeyPath) {
  int line = -1;
  const fs::path scn = patched_smoke("bad_prob.yaml", [&](std::string& text) {
    line = replace_once(text, "probability: 0.999", "probability: 1.5", text.find("gating:"));
  });
  ASSERT_GT(line, 0);
  expect_scenario_error(scn, line, "estimator.gating.probability");
}

TEST_F(CliTest, MissingScenarioFileFailsNamingTheFile) {
  const fs::path missing = tmp_ / "no_such_scenario.yaml";
  const fs::path out = out_dir();
  const RunResult r =
      run_wingman({"run", missing.string(), "--out", out.string(), "--no-plots", "-q"}, tmp_.path());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(missing.string())) << r.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());
}

TEST_F(CliTest, UnknownVariantExits2) {
  const fs::path out = out_dir();
  const RunResult r = run_wingman(
      {"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q", "--variant", "nope"},
      tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("nope"));
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CliTest, RunWritesCompleteResultsDirectory) {
  const fs::path out = out_dir("results");
  const RunResult r = run_wingman(
      {"run", "scenes/smoke.yaml", "--out", out.string(), "--no-plots", "-q", "--variant", "multi"},
      tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_regular_file(out / ".wingman-results"));
  EXPECT_TRUE(fs::is_regular_file(out / "scenario.yaml"));
  EXPECT_EQ(read_file(out / "scenario.yaml"), read_file(kSmoke));
  EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());

  // A selected variant is written into a folder named after it, as when all variants run.
  const fs::path dir = out / "multi";
  for (const char* f : {"metrics.json", "steps.csv", "landmarks.csv", "map.ply", "config.yaml",
                        "traj/lead.est.tum", "traj/lead.gt.tum", "traj/uav1.est.tum",
                        "traj/uav1.gt.tum", "traj/uav2.est.tum", "traj/uav2.gt.tum"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
    if (fs::is_regular_file(dir / f)) {
      EXPECT_GT(fs::file_size(dir / f), 0u) << f;
    }
  }
  EXPECT_FALSE(fs::exists(out / "single")) << "--variant multi ran the single variant too";
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    EXPECT_NE(e.path().extension(), ".png") << e.path();
  }

  // -q: nothing on stdout or stderr.
  EXPECT_EQ(r.output, "");

  const auto j = nlohmann::json::parse(read_file(dir / "metrics.json"));
  const auto& mse = j.at("table4").at("total").at("lead").at("mse");
  ASSERT_TRUE(mse.is_array());
  ASSERT_EQ(mse.size(), 3u);
  for (const auto& v : mse) {
    ASSERT_TRUE(v.is_number()) << mse;
    EXPECT_TRUE(std::isfinite(v.get<double>()));
    EXPECT_GE(v.get<double>(), 0.0);
  }
  EXPECT_EQ(j.at("agents"), nlohmann::json({"lead", "uav1", "uav2"}));
  EXPECT_EQ(j.at("scenario").at("variant"), "multi");

  // TUM: one line per step plus the header, 8 columns.
  const auto tum = lines_of(read_file(dir / "traj/lead.est.tum"));
  ASSERT_GE(tum.size(), 2u);
  EXPECT_EQ(tum.front().rfind("#", 0), 0u);
  EXPECT_EQ(static_cast<long>(tum.size()) - 1, j.at("steps").get<long>());
  std::istringstream row(tum[1]);
  int cols = 0;
  for (std::string tok; row >> tok;) ++cols;
  EXPECT_EQ(cols, 8);
  // Orientations, unit quaternions: the lead's turns about z only (its heading); the cameras' are
  // nadir, a half turn about the world's x (q_WC = (1, 0, 0, 0) in TUM's qx qy qz qw order, up to
  // the gimbal error).
  for (const char* f : {"traj/lead.gt.tum", "traj/lead.est.tum", "traj/uav1.gt.tum", "traj/uav1.est.tum"}) {
    const auto rows = lines_of(read_file(dir / f));
    for (std::size_t i = 1; i < rows.size(); ++i) {
      std::istringstream r(rows[i]);
      double t, x, y, z, qx, qy, qz, qw;
      ASSERT_TRUE(r >> t >> x >> y >> z >> qx >> qy >> qz >> qw) << f;
      ASSERT_NEAR(qx * qx + qy * qy + qz * qz + qw * qw, 1.0, 1e-6) << f << ": " << rows[i];
      if (std::string(f).find("lead") != std::string::npos)
        ASSERT_TRUE(qx == 0 && qy == 0) << f << ": a heading turns about z only: " << rows[i];
      else
        ASSERT_GT(std::abs(qx), 0.99) << f << ": a nadir camera: " << rows[i];
    }
  }
  // What evo computes from these files (unaligned translation APE over all N lines) is Table 4's
  // total scaled by (N-1)/N: step 0 starts at the truth and Table 4 leaves it out.
  {
    const auto est = lines_of(read_file(dir / "traj/lead.est.tum")), gt = lines_of(read_file(dir / "traj/lead.gt.tum"));
    ASSERT_EQ(est.size(), gt.size());
    double sum = 0;
    for (std::size_t i = 1; i < est.size(); ++i) {
      std::istringstream a(est[i]), b(gt[i]);
      double ta, tb, xa, ya, za, xb, yb, zb;
      ASSERT_TRUE(a >> ta >> xa >> ya >> za && b >> tb >> xb >> yb >> zb);
      sum += (xa - xb) * (xa - xb) + (ya - yb) * (ya - yb) + (za - zb) * (za - zb);
    }
    const double n = static_cast<double>(est.size() - 1);
    double table4 = 0;
    for (const auto& m : j.at("table4").at("total").at("lead").at("mse")) table4 += m.get<double>();
    EXPECT_NEAR(sum / n, (n - 1) / n * table4, 1e-6 * table4);
  }

  // Running again into the results directory is refused without --force; with it, replaces it.
  const auto before = fs::last_write_time(out / "multi" / "metrics.json");
  const RunResult refused = run_wingman(
      {"run", "scenes/smoke.yaml", "--out", out.string(), "--no-plots", "-q", "--variant", "single"},
      tmp_.path());
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_THAT(refused.output, HasSubstr("--force"));
  EXPECT_EQ(fs::last_write_time(out / "multi" / "metrics.json"), before);  // multi kept
  const RunResult again = run_wingman(
      {"run", "scenes/smoke.yaml", "--out", out.string(), "--no-plots", "-q", "--variant", "multi", "--force"},
      tmp_.path());
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(fs::is_regular_file(out / "multi" / "metrics.json"));
  EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());
}

TEST_F(CliTest, RenderRefusesToReplaceAResultsDirectory) {
  const fs::path out = out_dir("results");
  ASSERT_EQ(run_wingman({"run", "scenes/smoke.yaml", "--out", out.string(), "--no-plots", "-q", "--variant", "multi"},
                        tmp_.path()).exit_code, 0);
  const RunResult r = run_wingman({"render", "scenes/rendered_smoke.yaml", "--out", out.string(), "--frames", "1", "-q"},
                                  tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("already holds wingman results"));
  EXPECT_TRUE(fs::is_regular_file(out / "multi" / "metrics.json"));
  EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());
}

TEST_F(CliTest, RefusesExistingDirectoryThatIsNotAResultsDirectory) {
  const fs::path out = out_dir("precious");
  fs::create_directories(out);
  const std::string content = "do not delete: " + std::to_string(::getpid()) + "\n";
  write_file(out / "notes.txt", content);
  const auto before = fs::last_write_time(out / "notes.txt");

  const RunResult r = run_wingman(
      {"run", "scenes/smoke.yaml", "--out", out.string(), "--no-plots", "-q", "--variant", "multi"},
      tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(out.string()));
  ASSERT_TRUE(fs::is_regular_file(out / "notes.txt"));
  EXPECT_EQ(read_file(out / "notes.txt"), content);
  EXPECT_EQ(fs::last_write_time(out / "notes.txt"), before);
  std::set<std::string> entries;
  for (const auto& e : fs::directory_iterator(out)) entries.insert(e.path().filename().string());
  EXPECT_EQ(entries, std::set<std::string>{"notes.txt"});
  EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());
}

// steps.csv without its timing columns (wall-clock, never reproducible).
std::string steps_without_timings(const fs::path& csv) {
  const auto rows = lines_of(read_file(csv));
  if (rows.empty()) return {};
  auto split = [](const std::string& l) {
    std::vector<std::string> f;
    std::string cur;
    for (char c : l) {
      if (c == ',') {
        f.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    f.push_back(cur);
    return f;
  };
  const auto header = split(rows.front());
  std::vector<bool> keep;
  for (const auto& h : header) keep.push_back(!(h.rfind("t_", 0) == 0 && h.ends_with("_ms")));
  EXPECT_EQ(std::count(keep.begin(), keep.end(), false), 6) << rows.front();  // 3 EKF + 3 frontend stages
  std::string out;
  for (const auto& r : rows) {
    const auto f = split(r);
    EXPECT_EQ(f.size(), header.size());
    for (std::size_t i = 0; i < f.size() && i < keep.size(); ++i) {
      if (keep[i]) out += f[i] + ",";
    }
    out += "\n";
  }
  return out;
}

TEST_F(CliTest, SameSeedSameNumbersOtherSeedOtherNumbers) {
  auto run_seed = [&](const std::string& seed, const std::string& name) {
    const fs::path out = out_dir(name);
    const RunResult r = run_wingman({"run", "scenes/smoke.yaml", "--out", out.string(),
                                     "--no-plots", "-q", "--variant", "multi", "--seed", seed},
                                    tmp_.path());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return out / "multi";
  };
  const fs::path a = run_seed("7", "a"), b = run_seed("7", "b"), c = run_seed("8", "c");
  ASSERT_TRUE(fs::is_regular_file(a / "steps.csv"));
  ASSERT_TRUE(fs::is_regular_file(b / "steps.csv"));
  ASSERT_TRUE(fs::is_regular_file(c / "steps.csv"));

  const std::string sa = steps_without_timings(a / "steps.csv");
  EXPECT_EQ(sa, steps_without_timings(b / "steps.csv"));
  EXPECT_NE(sa, steps_without_timings(c / "steps.csv"));
  EXPECT_EQ(read_file(a / "landmarks.csv"), read_file(b / "landmarks.csv"));
  for (const char* f : {"traj/lead.est.tum", "traj/uav1.est.tum", "traj/uav2.est.tum", "map.ply"})
    EXPECT_EQ(read_file(a / f), read_file(b / f)) << f;

  const auto ja = nlohmann::json::parse(read_file(a / "metrics.json"));
  const auto jb = nlohmann::json::parse(read_file(b / "metrics.json"));
  const auto jc = nlohmann::json::parse(read_file(c / "metrics.json"));
  EXPECT_EQ(ja.at("scenario").at("seed"), 7);
  EXPECT_EQ(jc.at("scenario").at("seed"), 8);
  EXPECT_EQ(ja.at("table4"), jb.at("table4"));
  EXPECT_EQ(ja.at("table5"), jb.at("table5"));
  EXPECT_EQ(ja.at("table3"), jb.at("table3"));
  EXPECT_NE(ja.at("table4").at("total"), jc.at("table4").at("total"));
}

TEST_F(CliTest, HelpExitsZeroAndMentionsRun) {
  const RunResult top = run_wingman({"--help"}, tmp_.path());
  EXPECT_EQ(top.exit_code, 0) << top.output;
  EXPECT_THAT(top.output, HasSubstr("run"));
  const RunResult run = run_wingman({"run", "--help"}, tmp_.path());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("run"));
  EXPECT_THAT(run.output, HasSubstr("--out"));
  EXPECT_THAT(run.output, HasSubstr("--seed"));
}

// --video and --correspondences need rendered frames: refused on a synthetic scenario, before
// anything is written.
TEST_F(CliTest, RenderedOnlyOutputsAreRefusedOnSyntheticScenarios) {
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--correspondences"}, std::vector<std::string>{"--video", "v.avi"}}) {
    const fs::path out = out_dir();
    std::vector<std::string> args{"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = run_wingman(args, tmp_.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(extra[0] + " needs a scenario with measurements: rendered"));
    EXPECT_FALSE(fs::exists(out)) << extra[0];
    EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty()) << extra[0];
  }
}

// A rendered scenario whose world names a file that is not there is refused on loading, at the
// key's line, before anything is written; so is `wingman render` of a synthetic one.
TEST_F(CliTest, MissingWorldFilesExit2AtTheirKeyBeforeAnythingIsWritten) {
  const fs::path model = patched_smoke("model.yaml", [](std::string& t) {
    t.replace(t.find("measurements: synthetic"), 23, "measurements: rendered");
    t += "world:\n  lead: {kind: ground, model: models/nope.glb}\n";
  });
  expect_scenario_error(model, 62, "world.lead.model: 'models/nope.glb': file not found (looked at ");
  const fs::path image = patched_smoke("image.yaml", [](std::string& t) {
    t.replace(t.find("measurements: synthetic"), 23, "measurements: rendered");
    t += "world:\n  texture:\n    image: gone.jpg\n";
  });
  expect_scenario_error(image, 63, "world.texture.image: 'gone.jpg': file not found");

  const fs::path synthetic = patched_smoke("synthetic.yaml", [](std::string& t) {
    t += "world:\n  lead: {model: models/nope.glb}\n";
  });
  const fs::path out = out_dir("ds");
  const RunResult r = run_wingman({"render", synthetic.string(), "--out", out.string(), "-q"}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(synthetic.string() + ":62:17: world.lead.model: 'models/nope.glb'"));
  EXPECT_FALSE(fs::exists(out));
  EXPECT_THAT(partial_entries(tmp_.path()), ::testing::IsEmpty());
}

// A lead path and a team that cannot be flown: waypoints out of time order, a trajectory file with
// a malformed line, no UAVs. Each exits 2 at its key's line, naming the trajectory file's own
// line where there is one, and writes nothing.
TEST_F(CliTest, BadTrajectoriesAndAnEmptyTeamExit2AtTheirKey) {
  const fs::path order = patched_smoke("order.yaml", [](std::string& t) {
    t.replace(t.find("  trajectory: {type: lemniscate"), 0,
              "  trajectory:\n    type: waypoints\n    waypoints:\n      - [0, 0, 0, 0]\n      - [20, 30, 0, 0]\n"
              "      - [12, 40, 0, 0]\n#");
  });
  expect_scenario_error(order, 18, "lead.trajectory.waypoints[2]: time 12 is not after the previous waypoint's (20)");
  write_file(tmp_ / "track.csv", "t,x,y,z\n0,0,0,0\n1,1,0,0\n2,2,0\n");
  const fs::path file = patched_smoke("file.yaml", [](std::string& t) {
    t.replace(t.find("trajectory: {type: lemniscate"), 0, "trajectory: {type: file, file: track.csv}\n#");
  });
  expect_scenario_error(file, 13, "lead.trajectory.file: " + (tmp_ / "track.csv").string() +
                                      ":4: expected 4 fields (t,x,y,z), got 3");
  const fs::path empty = patched_smoke("empty.yaml", [](std::string& t) {
    const auto from = t.find("uavs:\n"), to = t.find("\nnoise:");
    t.replace(from, to - from, "uavs: []\n");
  });
  const RunResult r = run_wingman({"run", empty.string(), "--out", out_dir().string(), "-q"}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr(empty.string() + ":15:7: uavs: at least one UAV is needed")) << r.output;
  EXPECT_FALSE(fs::exists(out_dir()));
}

// A run's true lead trajectory (traj/lead.gt.tum), read back as the lead's trajectory file,
// reproduces its poses; the results keep the file next to scenario.yaml, and config.yaml runs
// the same flight from anywhere.
TEST_F(CliTest, TumTrajectoryReadBackReproducesTheLeadsPoses) {
  const fs::path first = out_dir("first");
  RunResult r = run_wingman({"run", kSmoke.string(), "--variant", "multi", "--duration", "6", "--out",
                             first.string(), "--no-plots", "-q"}, tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  fs::create_directories(tmp_ / "scn" / "tracks");
  fs::copy_file(first / "multi" / "traj" / "lead.gt.tum", tmp_ / "scn" / "tracks" / "lead.tum");
  const fs::path scn = tmp_ / "scn" / "follow.yaml";
  write_file(scn, "duration: 6\nlead: {trajectory: {type: file, file: tracks/lead.tum, ends: natural}}\n");
  const fs::path second = out_dir("second");
  r = run_wingman({"run", scn.string(), "--out", second.string(), "--no-plots", "-q"}, tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_file(second / "tracks" / "lead.tum"), read_file(tmp_ / "scn" / "tracks" / "lead.tum"));
  auto poses = [](const fs::path& f) {
    std::vector<std::vector<double>> rows;
    std::istringstream in(read_file(f));
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream ls(line);
      std::vector<double> v(8);
      for (double& x : v) ls >> x;
      rows.push_back(v);
    }
    return rows;
  };
  const auto a = poses(first / "multi" / "traj" / "lead.gt.tum"), b = poses(second / "traj" / "lead.gt.tum");
  ASSERT_EQ(a.size(), 61u);
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i][0], b[i][0], 1e-9) << i;
    for (int k = 1; k <= 3; ++k) EXPECT_NEAR(a[i][k], b[i][k], 1e-6) << i << " axis " << k;
    // The heading comes from the spline's velocity: the lemniscate's within a hundredth of a radian.
    const double dot = std::abs(a[i][4] * b[i][4] + a[i][5] * b[i][5] + a[i][6] * b[i][6] + a[i][7] * b[i][7]);
    EXPECT_GT(dot, std::cos(0.005)) << i << ": " << a[i][6] << " " << b[i][6];
  }
  // The resolved configuration names the file by its absolute path: it runs from its own folder.
  const fs::path third = out_dir("third");
  r = run_wingman({"run", (second / "config.yaml").string(), "--out", third.string(), "--no-plots", "-q"},
                  tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_file(third / "traj" / "lead.gt.tum"), read_file(second / "traj" / "lead.gt.tum"));
}

TEST_F(CliTest, BadCommandLineExits2) {
  const RunResult none = run_wingman({}, tmp_.path());
  EXPECT_EQ(none.exit_code, 2) << none.output;
  const RunResult bogus = run_wingman({"run", kSmoke.string(), "--no-such-flag"}, tmp_.path());
  EXPECT_EQ(bogus.exit_code, 2) << bogus.output;
  EXPECT_THAT(bogus.output, HasSubstr("no-such-flag"));
}

TEST_F(CliTest, UnknownCommandIsNamedWithTheValidOnes) {
  const RunResult r = run_wingman({"rnu", kSmoke.string()}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("error: unknown command 'rnu' (did you mean 'run'?); the commands are: run, "
                                  "montecarlo, observability, render, slam, bench-frontend"));
  const RunResult far = run_wingman({"fly", kSmoke.string()}, tmp_.path());
  EXPECT_EQ(far.exit_code, 2) << far.output;
  EXPECT_THAT(far.output, HasSubstr("error: unknown command 'fly'; the commands are"));
}

TEST_F(CliTest, ArgumentErrorsSayErrorAndWhereToLook) {
  const RunResult missing = run_wingman({"montecarlo", kSmoke.string()}, tmp_.path());
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("error: --runs is required"));
  EXPECT_THAT(missing.output, HasSubstr("--help"));
  const RunResult both = run_wingman({"run", kSmoke.string(), "--duration", "2", "--frames", "5"}, tmp_.path());
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_THAT(both.output, HasSubstr("error: --duration excludes --frames"));
}

TEST_F(CliTest, AnEmptyOutputDirectoryMadeBeforeTheRunIsFilled) {
  const fs::path out = out_dir("made_by_ci");
  fs::create_directories(out);
  const RunResult r = run_wingman({"run", kSmoke.string(), "--variant", "multi", "--duration", "1", "--no-plots",
                                   "-q", "--out", out.string()},
                                  tmp_.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "multi" / "metrics.json"));
}

// --print-config prints each selected variant's resolved configuration, the config.yaml a run
// writes; --frames N and --duration (N-1)/rate keep the same steps.
TEST_F(CliTest, PrintConfigIsTheWrittenConfigAndStepLimitsAgree) {
  const RunResult printed =
      run_wingman({"run", "scenes/smoke.yaml", "--variant", "single", "--print-config"}, tmp_.path());
  ASSERT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_THAT(printed.output, HasSubstr("mode: single"));
  EXPECT_THAT(printed.output, HasSubstr("orientation_sigma: 0.028"));
  const fs::path a = out_dir("frames"), b = out_dir("duration");
  ASSERT_EQ(run_wingman({"run", "scenes/smoke.yaml", "--variant", "single", "--frames", "31", "--out",
                         a.string(), "--no-plots", "-q"},
                        tmp_.path())
                .exit_code,
            0);
  ASSERT_EQ(run_wingman({"run", "scenes/smoke.yaml", "--variant", "single", "--duration", "3", "--out",
                         b.string(), "--no-plots", "-q"},
                        tmp_.path())
                .exit_code,
            0);
  EXPECT_EQ(read_file(a / "single" / "config.yaml"), read_file(b / "single" / "config.yaml"));
  EXPECT_THAT(read_file(a / "single" / "config.yaml"), HasSubstr("duration: 3\n"));
  const auto m = nlohmann::json::parse(read_file(a / "single" / "metrics.json"));
  EXPECT_EQ(m["steps"].get<int>(), 31);
  EXPECT_EQ(run_wingman({"run", "scenes/smoke.yaml", "--frames", "1"}, tmp_.path()).exit_code, 2);
}

}  // namespace
}  // namespace wingman::app::test
