// `wingman render` end to end: a small scenario renders into a dataset that reads back and
// whose frames equal a direct render; bad input exits 2 naming the file; Ctrl-C leaves nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <functional>
#include <thread>

#include "app/config/run_config.hpp"
#include "app/app_test_support.hpp"
#include "gl_required.hpp"
#include "datasets/dataset.hpp"
#include "render/gl_context.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "sim/truth.hpp"

namespace wingman::app::test {
namespace {

std::string tiny_scenario(double duration, const std::string& world = "{texture: {anisotropy: 4}}") {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
  const std::string cam = "camera: {fx: 40.02, fy: 40.02, cx: 99.5, cy: 99.5, width: 200, height: 200}";
  std::string s = "name: tiny\nrate: 10\nduration: ";
  s += std::to_string(duration);
  s += "\nuavs:\n  - {name: uav1, initial_position: [-1.5, 0, 15], sees_lead: true, altimeter: true, range: true, ";
  s += cam;
  s += "}\n  - {name: uav2, initial_position: [1.5, 0, 17], range: false, ";
  s += cam;
  s += "}\nworld: ";
  s += world;
  s += "\n";
  return s;
}

// Without --out a dataset lands under results/ (ignored by git), never among the sources; a
// rendered run and a replay of it say where their frames came from, and a replay calls loading
// its frames what it is.
TEST(RenderCli, DefaultOutputIsUnderResultsAndSummariesNameTheFramesSource) {
  TempDir tmp;
  const fs::path scn = tmp / "tiny.yaml";
  write_file(scn, tiny_scenario(0.2) + "measurements: rendered\n");
  const auto r = run_wingman({"render", scn.string(), "--gl", "osmesa", "-q"}, tmp.path(), tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path ds = tmp / "results" / "datasets" / "tiny";
  EXPECT_TRUE(fs::exists(ds / "dataset.yaml")) << r.output;

  const auto run = run_wingman({"run", scn.string(), "--gl", "osmesa", "--no-plots", "--out", (tmp / "run").string()},
                               tmp.path());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, ::testing::HasSubstr("Frames from: "));
  EXPECT_THAT(run.output, ::testing::HasSubstr("Stages [ms/step, mean]: render "));
  const auto replay = run_wingman({"slam", ds.string(), "--no-plots", "--out", (tmp / "replay").string()}, tmp.path());
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_THAT(replay.output, ::testing::HasSubstr("Frames from: dataset replay"));
  EXPECT_THAT(replay.output, ::testing::HasSubstr("Stages [ms/step, mean]: load frames "));
  // The same count in the progress line's last state and the summary: t = 0 and 2 more steps.
  EXPECT_THAT(replay.output, ::testing::HasSubstr(", 3 steps,"));
}

TEST(RenderCli, WritesADatasetThatReadsBackAndMatchesADirectRender) {
  TempDir tmp;
  const fs::path scn = tmp / "tiny.yaml";
  write_file(scn, tiny_scenario(0.1));
  const fs::path out = tmp / "ds";
  const auto r = run_wingman({"render", scn.string(), "--out", out.string(), "--gl", "osmesa", "--seed", "5"}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const datasets::Dataset ds = datasets::read_dataset(out);
  EXPECT_EQ(ds.info.frames, 2);
  EXPECT_EQ(ds.info.seed, 5u);
  EXPECT_EQ(ds.info.scenario, "tiny");
  EXPECT_NE(ds.info.renderer.find("osmesa"), std::string::npos);
  EXPECT_EQ(ds.agent("uav1").altimeter.size(), 2u);
  EXPECT_EQ(ds.agent("lead").gps.size(), 2u);
  EXPECT_EQ(ds.agent("uav2").altimeter.size(), 2u);  // carried unless switched off
  EXPECT_TRUE(ds.agent("uav2").range.empty());          // switched off: no samples
  EXPECT_TRUE(fs::exists(out / "scenario.yaml"));

  std::unique_ptr<render::GlContext> ctx;
  try {
    ctx = render::create_gl_context(render::GlBackend::OsMesa);
  } catch (const render::GlContextError& e) {
    WINGMAN_NO_GL_CONTEXT(e.what());
  }
  app::RunConfig s = app::load_run_configs(scn.string()).front();
  s.seed = 5;
  const sim::OpenLoopTruth truth(s);
  render::Renderer renderer(*ctx, render::build_scene(sim::describe_world(s)));
  const double t = 0.1;
  const render::Frame f = renderer.render(
      {s.uavs[1].camera.camera(), truth.camera_R_CW(1, t), truth.camera(1, t).position},
      sim::lead_pose(truth, t, s.world));
  EXPECT_EQ(cv::norm(ds.load_image("uav2", 100000000), f.gray(), cv::NORM_INF), 0);  // grey by default
  EXPECT_LT((ds.agent("uav2").camera_pose[1].p - truth.camera(1, t).position).norm(), 1e-6);
}

TEST(RenderCli, BadInputExitsTwoNamingTheFile) {
  TempDir tmp;
  const fs::path scn = tmp / "bad.yaml";
  write_file(scn, tiny_scenario(0.1, "{lead: {model: no_such_model.glb}}"));
  auto r = run_wingman({"render", scn.string(), "--out", (tmp / "ds").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(scn.string() + ":7:23: world.lead.model: 'no_such_model.glb': file not found"),
            std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(tmp / "ds"));

  write_file(scn, tiny_scenario(0.1, "{terrain: {relief: -1}}"));
  r = run_wingman({"render", scn.string(), "--out", (tmp / "ds").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("world.terrain.relief"), std::string::npos) << r.output;

  write_file(scn, tiny_scenario(0.1));
  r = run_wingman({"render", scn.string(), "--out", (tmp / "ds").string(), "--gl", "vulkan"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;

  fs::create_directories(tmp / "precious");
  write_file(tmp / "precious" / "thesis.tex", "x");
  r = run_wingman({"render", scn.string(), "--out", (tmp / "precious").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(fs::exists(tmp / "precious" / "thesis.tex"));
}

// `wingman slam` checks a dataset as a whole before its first step: every failure is bad input
// (exit 2) naming the file, and nothing is written.
TEST(RenderCli, SlamRefusesADatasetThatContradictsItsScenarioOrIsDamaged) {
  TempDir tmp;
  const fs::path scn = tmp / "tiny.yaml";
  write_file(scn, tiny_scenario(0.3));
  const fs::path ds = tmp / "ds";
  const auto r = run_wingman({"render", scn.string(), "--out", ds.string(), "--gl", "osmesa"}, tmp.path());
  if (r.exit_code != 0 && r.output.find("OSMesa") != std::string::npos) WINGMAN_NO_GL_CONTEXT(r.output);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path out = tmp / "res";
  ASSERT_EQ(run_wingman({"slam", ds.string(), "--out", out.string(), "--no-plots", "-q"}, tmp.path()).exit_code, 0);
  fs::remove_all(out);

  struct Case {
    std::function<void(const fs::path&)> damage;
    std::string names;
  };
  const std::vector<Case> cases = {
      {[](const fs::path& d) {  // the scenario says 100 x 100 over 200 x 200 frames
         std::string t = read_file(d / "scenario.yaml");
         replace_once(t, "width: 200, height: 200}}\n  - {name: uav2", "width: 100, height: 100}}\n  - {name: uav2");
         write_file(d / "scenario.yaml", t);
       },
       "uav1/mav0/cam0/sensor.yaml: the camera (200x200"},
      {[](const fs::path& d) {
         std::string t = read_file(d / "dataset.yaml");
         replace_once(t, "agents: [lead, uav1, uav2]", "agents: [lead, uav1]");
         write_file(d / "dataset.yaml", t);
       },
       "dataset.yaml: agents: no 'uav2'"},
      {[](const fs::path& d) {
         const fs::path f = d / "uav2" / "mav0" / "cam0" / "data" / "200000000.png";
         std::string b = read_file(f);
         b[b.size() - 100] ^= 0x10;
         write_file(f, b);
       },
       "uav2/mav0/cam0/data/200000000.png: CRC-32"},
      {[](const fs::path& d) { fs::remove_all(d / "uav1" / "mav0" / "imu0"); },
       "uav1/mav0/imu0: missing sensor folder (every UAV carries an IMU)"},
      {[](const fs::path& d) {  // a malformed IMU row
         std::string t = read_file(d / "uav2" / "mav0" / "imu0" / "data.csv");
         replace_once(t, "\n5000000,", "\n5000000,x,");
         write_file(d / "uav2" / "mav0" / "imu0" / "data.csv", t);
       },
       "uav2/mav0/imu0/data.csv: line 3: expected 7 columns, got 8"},
  };
  for (const Case& c : cases) {
    const fs::path copy = tmp / "copy";
    fs::remove_all(copy);
    fs::copy(ds, copy, fs::copy_options::recursive);
    c.damage(copy);
    const auto s = run_wingman({"slam", copy.string(), "--out", out.string(), "--no-plots", "-q"}, tmp.path());
    EXPECT_EQ(s.exit_code, 2) << s.output;
    EXPECT_NE(s.output.find((copy / c.names).string()), std::string::npos) << s.output;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(RenderCli, InterruptLeavesNoDatasetBehind) {
  TempDir tmp;
  const fs::path scn = tmp / "long.yaml";
  write_file(scn, tiny_scenario(200));
  const fs::path out = tmp / "ds";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int fd = ::open("/dev/null", O_WRONLY);
    dup2(fd, 1);
    dup2(fd, 2);
#ifdef __SANITIZE_ADDRESS__
    // GCC 12's LeakSanitizer crashes at this exit (its tracer reads a bogus dynamic-TLS range left
    // by the GL libraries opened at run time: "Tracer caught signal 11 ... LeakSanitizer has
    // encountered a fatal error"), which turns the exit status into 1; this test checks the
    // status and the cleanup, and every other test keeps leak checking.
    setenv("ASAN_OPTIONS", "detect_leaks=0", 1);
#endif
    execl(kBinary.c_str(), "wingman", "render", scn.c_str(), "--out", out.c_str(), "--gl", "osmesa",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until frames are being written into the staging directory, then interrupt.
  bool writing = false;
  for (int i = 0; i < 600 && !writing; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    for (const auto& e : fs::directory_iterator(tmp.path()))
      if (e.path().filename().string().rfind("ds.partial", 0) == 0 &&
          fs::exists(e.path() / "uav1" / "mav0" / "cam0" / "data" / "100000000.png"))
        writing = true;
  }
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(writing);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(tmp.path()))
    EXPECT_EQ(e.path().filename().string().find("ds."), std::string::npos) << e.path();
}

}  // namespace
}  // namespace wingman::app::test
