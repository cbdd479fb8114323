// Nothing lost, nothing silent: interrupted and killed runs, existing results, numerical
// failures of the filter and Monte Carlo directories resumed with other settings, each through
// the real `wingman` binary.
// GCC 12 warns falsely about std::string concatenation inlined from gtest (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"

namespace wingman::app::test {
namespace {

using ::testing::HasSubstr;
using ::testing::IsEmpty;

// smoke.yaml flown for `seconds`: long enough to interrupt while it computes.
fs::path long_smoke(const TempDir& tmp, double seconds) {
  std::string text = read_file(kSmoke);
  replace_top_level_value(text, "duration", std::to_string(seconds));
  replace_once(text, "to: 24, config: 3}", "to: " + std::to_string(seconds) + ", config: 3}");
  const fs::path p = tmp / "long.yaml";
  write_file(p, text);
  return p;
}

// Entries of dir whose names start with `prefix` and hold ".partial-" or ".old-".
std::vector<std::string> leftovers(const fs::path& dir, const std::string& prefix) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(prefix, 0) == 0 && (n.find(".partial-") != std::string::npos || n.find(".old-") != std::string::npos))
      v.push_back(n);
  }
  return v;
}

// Starts `wingman args...` with its output to `log`, waits until its staging directory for
// `out` exists plus `after`, and sends `sig`. Returns the wait status.
int signal_while_running(const std::vector<std::string>& args, const fs::path& out, const fs::path& log,
                         int sig, std::chrono::milliseconds after = std::chrono::milliseconds(300)) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    std::vector<char*> argv{const_cast<char*>("wingman")};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(kBinary.c_str(), argv.data());
    _exit(127);
  }
  const std::string staging = out.filename().string() + ".partial-" + std::to_string(pid);
  for (int i = 0; i < 600 && !fs::exists(out.parent_path() / staging); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_TRUE(fs::exists(out.parent_path() / staging)) << "the run never started writing";
  std::this_thread::sleep_for(after);
  kill(pid, sig);
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

TEST(ResultsIntegrity, RunStopsOnSigintAndSigtermWithNothingWritten) {
  TempDir tmp;
  const fs::path scn = long_smoke(tmp, 2000);
  const fs::path out = tmp / "res";
  for (const auto& [sig, code] : {std::pair{SIGINT, 130}, std::pair{SIGTERM, 143}}) {
    const int st = signal_while_running({"run", scn.string(), "--out", out.string(), "--no-plots", "-q"}, out,
                                        tmp / "log.txt", sig);
    ASSERT_TRUE(WIFEXITED(st)) << "killed by the signal instead of stopping";
    EXPECT_EQ(WEXITSTATUS(st), code);
    EXPECT_THAT(read_file(tmp / "log.txt"), HasSubstr("interrupted by SIG"));
    EXPECT_FALSE(fs::exists(out));
    EXPECT_THAT(leftovers(tmp.path(), "res"), IsEmpty());
  }
}

TEST(ResultsIntegrity, KilledRunLosesNoResultAndItsStagingIsRemovedByTheNext) {
  TempDir tmp;
  const fs::path out = tmp / "res";
  ASSERT_EQ(run_wingman({"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q"}, tmp.path()).exit_code, 0);
  const std::string before = read_file(out / "multi" / "metrics.json");
  // SIGKILL cannot be handled: the staging directory stays, the previous result is untouched.
  const fs::path scn = long_smoke(tmp, 2000);
  const int st = signal_while_running({"run", scn.string(), "--out", out.string(), "--no-plots", "-q", "--force"},
                                      out, tmp / "log.txt", SIGKILL);
  ASSERT_TRUE(WIFSIGNALED(st));
  EXPECT_EQ(read_file(out / "multi" / "metrics.json"), before);
  ASSERT_EQ(leftovers(tmp.path(), "res").size(), 1u);
  // The next run into the same place finds it, names it and removes it.
  const RunResult r = run_wingman({"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q", "--force"},
                                  tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("note: removed " + (tmp / "res.partial-").string()));
  EXPECT_THAT(r.output, HasSubstr("which is gone"));
  EXPECT_THAT(leftovers(tmp.path(), "res"), IsEmpty());
}

TEST(ResultsIntegrity, AddingAVariantToExistingResultsIsRefused) {
  TempDir tmp;
  const fs::path out = tmp / "res";
  ASSERT_EQ(run_wingman({"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q"}, tmp.path()).exit_code, 0);
  const RunResult r = run_wingman(
      {"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q", "--variant", "single"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(out.string() + "' already holds wingman results"));
  EXPECT_TRUE(fs::exists(out / "multi" / "metrics.json"));  // never partly deleted
  EXPECT_TRUE(fs::exists(out / "single" / "metrics.json"));
}

TEST(ResultsIntegrity, NumericalFailureOfTheFilterIsAnErrorAtItsStep) {
  TempDir tmp;
  std::string text = read_file(kSmoke);
  // A filter GPS sigma of 1e-9 m: the covariance loses positive definiteness in its update.
  const int line = replace_once(text, "gps_sigma: 1.5, altimeter", "gps_sigma: 1e-9, altimeter");
  ASSERT_GT(line, 0);
  write_file(tmp / "gps.yaml", text);
  const fs::path out = tmp / "res";
  const RunResult r = run_wingman({"run", (tmp / "gps.yaml").string(), "--out", out.string(), "--no-plots", "-q"},
                                  tmp.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("gps.yaml: step "));
  EXPECT_THAT(r.output, HasSubstr("numerical failure in the filter after the sensor update (the GPS fix"));
  EXPECT_THAT(r.output, HasSubstr("camera 0 is uav1"));
  EXPECT_FALSE(fs::exists(out));
  EXPECT_THAT(leftovers(tmp.path(), "res"), IsEmpty());

  // Asked to record instead: the steps before the failure are the results, and say so.
  text = read_file(tmp / "gps.yaml");
  replace_once(text, "  single_uav: uav1\n", "  single_uav: uav1\n  on_numerical_failure: record\n");
  write_file(tmp / "rec.yaml", text);
  const RunResult rec = run_wingman(
      {"run", (tmp / "rec.yaml").string(), "--out", out.string(), "--no-plots", "--variant", "multi"}, tmp.path());
  EXPECT_EQ(rec.exit_code, 0) << rec.output;
  EXPECT_THAT(rec.output, HasSubstr("NUMERICAL FAILURE, the results end before it: "));
  const auto metrics = nlohmann::json::parse(read_file(out / "multi" / "metrics.json"));
  ASSERT_TRUE(metrics["numerical_failure"].is_object()) << metrics["numerical_failure"];
  const int step = metrics["numerical_failure"]["step"];
  EXPECT_GT(step, 1);
  EXPECT_EQ(metrics["steps"], step);  // steps 0 .. step - 1
  EXPECT_THAT(metrics["numerical_failure"]["message"].get<std::string>(), HasSubstr("numerical failure in the filter"));
  EXPECT_EQ(lines_of(read_file(out / "multi" / "steps.csv")).size(), static_cast<std::size_t>(step) + 1);
  fs::remove_all(out);

  // Noise no sensor has is refused before the run, rather than breaking the filter during it.
  text = read_file(kSmoke);
  replace_once(text, "  pixel_sigma: 3\n", "  pixel_sigma: 1e6\n");
  write_file(tmp / "px.yaml", text);
  const RunResult p = run_wingman({"run", (tmp / "px.yaml").string(), "--out", out.string(), "--no-plots", "-q"},
                                  tmp.path());
  EXPECT_EQ(p.exit_code, 2) << p.output;
  EXPECT_THAT(p.output, HasSubstr("px.yaml:28:16: noise.pixel_sigma: must be in [0, 1000], got 1e6"));
  EXPECT_FALSE(fs::exists(out));
}

TEST(ResultsIntegrity, MonteCarloRefusesToResumeWithOtherSettings) {
  TempDir tmp;
  const fs::path out = tmp / "mc";
  RunResult r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "1", "--out", out.string(), "--no-plots",
                             "-q", "--variant", "multi"},
                            tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string before = read_file(out / "montecarlo.json");
  std::string text = read_file(kSmoke);
  replace_once(text, "pixel_sigma: 3, gps", "pixel_sigma: 2, gps");
  write_file(tmp / "other.yaml", text);
  r = run_wingman({"montecarlo", (tmp / "other.yaml").string(), "--runs", "2", "--out", out.string(), "--no-plots",
                   "-q", "--variant", "multi", "--resume"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("its runs were made with other settings"));
  EXPECT_THAT(r.output, HasSubstr("key estimator.measurement_noise.pixel_sigma"));
  EXPECT_FALSE(fs::exists(out / "runs" / "seed2"));
  EXPECT_EQ(read_file(out / "montecarlo.json"), before);
  // Other options count too: a --duration limit changes every run.
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "2", "--out", out.string(), "--no-plots", "-q",
                   "--variant", "multi", "--resume", "--duration", "10"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("duration_limit"));
  // The same settings resume.
  r = run_wingman({"montecarlo", kSmoke.string(), "--runs", "2", "--out", out.string(), "--no-plots", "-q",
                   "--variant", "multi", "--resume"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "runs" / "seed2" / "multi" / "metrics.json"));
}

// A SIGKILL of `wingman montecarlo` cannot be handled, but its workers notice (the kernel sends
// them SIGTERM when their parent dies): they stop and remove their staging directories.
TEST(ResultsIntegrity, KilledMonteCarloTakesItsWorkersWithIt) {
  TempDir tmp;
  const fs::path scn = long_smoke(tmp, 2000);
  const fs::path out = tmp / "mc";
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open((tmp / "log.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    execl(kBinary.c_str(), "wingman", "montecarlo", scn.c_str(), "--runs", "2", "--jobs", "2", "--out",
          out.c_str(), "--no-plots", "--variant", "multi", static_cast<char*>(nullptr));
    _exit(127);
  }
  auto staging = [&] { return fs::exists(out / "runs") ? leftovers(out / "runs", "seed") : std::vector<std::string>{}; };
  for (int i = 0; i < 600 && staging().size() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_EQ(staging().size(), 2u) << "the workers never started";
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  for (int i = 0; i < 200 && !staging().empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_THAT(staging(), IsEmpty()) << "orphaned workers kept running";
  EXPECT_FALSE(fs::exists(out / "montecarlo.json"));
}

// A results directory that exists is complete: the marker, and every variant's metrics.json.
bool complete(const fs::path& out) {
  return fs::exists(out / ".wingman-results") && fs::exists(out / "multi" / "metrics.json") &&
         fs::exists(out / "single" / "metrics.json");
}

// Signals at random times over a run's whole life (starting, computing, writing, committing),
// onto a directory that already holds a result: whatever the moment, DIR is either the old result
// or a complete new one, never missing or partial; the next run cleans up whatever was left.
TEST(ResultsIntegrity, SignalsAtRandomTimesNeverLoseOrFakeAResult) {
  TempDir tmp;
  const fs::path out = tmp / "res";
  ASSERT_EQ(run_wingman({"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q"}, tmp.path()).exit_code, 0);
  std::mt19937 rng(2026);
  std::uniform_int_distribution<int> delay_ms(0, 900);
  const int signals[] = {SIGINT, SIGTERM, SIGKILL};
  for (int trial = 0; trial < 12; ++trial) {
    const int sig = signals[trial % 3];
    const pid_t pid = fork();
    if (pid == 0) {
      const int fd = ::open("/dev/null", O_WRONLY);
      dup2(fd, 1);
      dup2(fd, 2);
      execl(kBinary.c_str(), "wingman", "run", kSmoke.c_str(), "--out", out.c_str(), "--no-plots", "-q", "--force",
            static_cast<char*>(nullptr));
      _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    kill(pid, sig);
    int st = 0;
    waitpid(pid, &st, 0);
    const bool finished = WIFEXITED(st) && WEXITSTATUS(st) == 0;
    if (!finished && WIFEXITED(st)) {
      EXPECT_EQ(WEXITSTATUS(st), 128 + sig) << "trial " << trial;
    }
    EXPECT_TRUE(complete(out)) << "trial " << trial << " (signal " << sig << "): the result is gone or partial";
    // A handled signal leaves nothing of its own (a SIGKILL's leftovers wait for the next run).
    if (sig != SIGKILL && WIFEXITED(st)) {
      EXPECT_FALSE(fs::exists(tmp / ("res.partial-" + std::to_string(pid)))) << "trial " << trial;
    }
  }
  const RunResult r = run_wingman({"run", kSmoke.string(), "--out", out.string(), "--no-plots", "-q", "--force"},
                                  tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(complete(out));
  EXPECT_THAT(leftovers(tmp.path(), "res"), IsEmpty());
}

}  // namespace
}  // namespace wingman::app::test
