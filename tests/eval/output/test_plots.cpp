#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <string>

#include "eval/metrics/metrics.hpp"
#include "eval/output/plots.hpp"
#include "eval/output/writers.hpp"
#include "eval/eval_test_support.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;

bool has_png_signature(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::array<unsigned char, 8> sig{};
  in.read(reinterpret_cast<char*>(sig.data()), sig.size());
  const std::array<unsigned char, 8> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return in.gcount() == 8 && sig == png;
}

TEST(Plots, WritesPngsAndScripts) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot with pngcairo is not installed";
  test::TempDir tmp;
  const RunRecord run = test::make_record();
  write_results(compute_metrics(run), run, tmp.path());
  const std::vector<fs::path> pngs = write_plots(run, tmp.path());
  EXPECT_EQ(pngs.size(), 2 * run.agent_names.size() + 2);
  for (const char* name : {"trajectory_lead", "trajectory_uav1", "errors_lead", "errors_uav1",
                           "landmarks", "nees"}) {
    const fs::path png = tmp.path() / "plots" / (std::string(name) + ".png");
    ASSERT_TRUE(fs::is_regular_file(png)) << png;
    EXPECT_GT(fs::file_size(png), 1000u) << png;
    EXPECT_TRUE(has_png_signature(png)) << png;
    EXPECT_TRUE(fs::is_regular_file(tmp.path() / "plots" / (std::string(name) + ".gp")));
  }
}

TEST(Plots, FailureNamesThePlot) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot with pngcairo is not installed";
  test::TempDir tmp;
  RunRecord run = test::make_record();
  write_steps_csv(run, tmp.path() / "steps.csv");
  run.agent_names.push_back("ghost");  // no such columns in steps.csv
  try {
    write_plots(run, tmp.path());
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("trajectory_ghost"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--no-plots"), std::string::npos) << msg;
  }
}

TEST(Plots, ComparisonOverlaysRuns) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot with pngcairo is not installed";
  test::TempDir tmp;
  RunRecord multi = test::make_record();
  RunRecord single = test::make_record();
  for (StepRecord& s : single.steps) s.agents[1].p_est += Eigen::Vector3d(1, 1, 1);
  write_results(compute_metrics(multi), multi, tmp.path() / "multi");
  write_results(compute_metrics(single), single, tmp.path() / "single");
  const fs::path out = tmp.path() / "cmp" / "uav1_errors.png";
  plot_comparison({(tmp.path() / "multi").string(), (tmp.path() / "single").string()},
                  {"multi-UAV", "single-UAV"}, "uav1", out.string());
  EXPECT_TRUE(has_png_signature(out));
  EXPECT_TRUE(fs::is_regular_file(tmp.path() / "cmp" / "uav1_errors.gp"));

  EXPECT_THROW(plot_comparison({(tmp.path() / "multi").string()}, {"a", "b"}, "uav1",
                               out.string()),
               std::invalid_argument);
  EXPECT_THROW(plot_comparison({(tmp.path() / "multi").string()}, {"a"}, "uav9", out.string()),
               std::invalid_argument);
}

}  // namespace
}  // namespace wingman::eval
