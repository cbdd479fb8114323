// `wingman montecarlo --engine slurm` against a real one-node Slurm cluster (munged, slurmctld
// and slurmd started by tools/slurm-local.sh in a temporary directory, stopped at the end of each
// test whatever happens): the same montecarlo.json as the local engine for the same seeds, progress,
// a failed task, --detach then --resume, Ctrl-C, and bad input. Without root or Slurm the cluster
// tests are skipped saying why; under CI=true (root, setup.sh installs Slurm) they fail instead.
// GCC 12 warns falsely about std::string concatenation inlined from gtest (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/app_test_support.hpp"
#include "gl_required.hpp"

extern char** environ;

using namespace wingman::app::test;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

const fs::path kClusterScript = kSourceDir / "tools" / "slurm-local.sh";

bool ci_requires_slurm() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

bool on_path(const std::string& name) {
  return std::system(("PATH=\"$PATH:/usr/sbin:/sbin\" command -v " + name + " > /dev/null 2>&1").c_str()) == 0;
}

// Why a local cluster cannot be started here, or "" when it can.
std::string missing_prerequisite() {
  if (::geteuid() != 0) return "not root: tools/slurm-local.sh runs the Slurm daemons as root";
  for (const char* cmd : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "sinfo"})
    if (!on_path(cmd)) return std::string("Slurm is not installed (no ") + cmd + "; setup.sh installs slurm-wlm and munge)";
  return "";
}

// A one-node cluster under dir for the test's lifetime; the clients find it through SLURM_CONF.
class LocalCluster {
 public:
  explicit LocalCluster(const fs::path& dir) : dir_(dir) {
    const std::string cmd = "bash " + quote(kClusterScript.string()) + " start " + quote(dir.string()) + " > " +
                            quote((dir.parent_path() / "cluster-start.txt").string()) + " 2>&1";
    up_ = std::system(cmd.c_str()) == 0;
    start_output_ = read_file(dir.parent_path() / "cluster-start.txt");
    if (up_) ::setenv("SLURM_CONF", (dir / "slurm.conf").c_str(), 1);
  }
  ~LocalCluster() {
    const std::string cmd = "bash " + quote(kClusterScript.string()) + " stop " + quote(dir_.string()) + " > /dev/null 2>&1";
    if (std::system(cmd.c_str()) != 0) ADD_FAILURE() << "tools/slurm-local.sh stop failed for " << dir_;
    ::unsetenv("SLURM_CONF");
  }
  LocalCluster(const LocalCluster&) = delete;
  LocalCluster& operator=(const LocalCluster&) = delete;
  bool up() const { return up_; }
  const std::string& start_output() const { return start_output_; }

 private:
  fs::path dir_;
  bool up_ = false;
  std::string start_output_;
};

// Skips (or, under CI=true, fails) the test when no cluster can be had; else starts one.
#define START_LOCAL_CLUSTER(cluster, dir)                                                              \
  if (const std::string why = missing_prerequisite(); !why.empty()) {                                 \
    if (ci_requires_slurm()) FAIL() << "CI=true and no Slurm cluster can be started: " << why;        \
    GTEST_SKIP() << why;                                                                               \
  }                                                                                                    \
  LocalCluster cluster(dir);                                                                           \
  ASSERT_TRUE(cluster.up()) << cluster.start_output()

std::vector<std::string> mc_args(const fs::path& out, int runs, const std::vector<std::string>& more = {}) {
  std::vector<std::string> a = {"montecarlo", kSmoke.string(), "--runs", std::to_string(runs), "--out", out.string(),
                                "--no-plots", "--variant", "multi"};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

std::string squeue_of(const std::string& job) {
  const fs::path f = fs::temp_directory_path() / ("wingman-squeue-" + std::to_string(::getpid()));
  std::system(("squeue -h -r -j " + job + " -o '%i %t' > " + quote(f.string()) + " 2>&1").c_str());
  const std::string text = read_file(f);
  fs::remove(f);
  return text;
}

// The first job id in slurm/jobs.
std::string first_job(const fs::path& out) {
  const std::string jobs = read_file(out / "slurm" / "jobs");
  return jobs.substr(0, jobs.find(' '));
}

}  // namespace

TEST(MonteCarloSlurm, GivesTheLocalEnginesMonteCarloJsonAndShowsProgress) {
  TempDir tmp;
  START_LOCAL_CLUSTER(cluster, tmp / "cluster");
  const fs::path slurm = tmp / "slurm", local = tmp / "local";
  const auto t0 = std::chrono::steady_clock::now();
  const RunResult s = run_wingman(mc_args(slurm, 4, {"--engine", "slurm", "--array-limit", "2", "--time", "10"}), tmp.path());
  const double slurm_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const RunResult l = run_wingman(mc_args(local, 4, {"--jobs", "2"}), tmp.path());
  ASSERT_EQ(l.exit_code, 0) << l.output;
  RecordProperty("slurm_seconds", std::to_string(slurm_s));

  // The same seeds give the same bytes: nothing in the aggregate depends on where a run ran.
  EXPECT_EQ(read_file(slurm / "montecarlo.json"), read_file(local / "montecarlo.json"));
  EXPECT_EQ(read_file(slurm / "nees.csv"), read_file(local / "nees.csv"));
  // A run's own metrics.json differs only in its wall-clock timings, which montecarlo.json leaves out.
  auto metrics = [](const fs::path& mc) {
    auto m = nlohmann::json::parse(read_file(mc / "runs" / "seed3" / "multi" / "metrics.json"));
    m.erase("timings_ms");
    m.erase("wall_time_s");
    return m;
  };
  EXPECT_EQ(metrics(slurm), metrics(local));
  EXPECT_EQ(nlohmann::json::parse(read_file(slurm / "montecarlo.json"))["seeds"], nlohmann::json::array({1, 2, 3, 4}));

  // Progress: submission, then the tasks' states as they end (stderr is a file: a line per 10 %).
  EXPECT_THAT(s.output, HasSubstr("submitted Slurm job")) << s.output;
  EXPECT_THAT(s.output, HasSubstr("[montecarlo]   0% 0/4")) << s.output;
  EXPECT_THAT(s.output, HasSubstr("[montecarlo] 100% 4/4 runs (0 running, 0 pending, 0 failed)")) << s.output;
  EXPECT_THAT(s.output, HasSubstr("4 runs finished (seeds 1..4), 0 failed")) << s.output;

  // The script: one task per seed, at most 2 at once, the options as #SBATCH lines.
  const std::string script = read_file(slurm / "slurm" / "array-1.sbatch");
  EXPECT_THAT(script, HasSubstr("#SBATCH --array=0-3%2\n"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --time=10\n"));
  EXPECT_THAT(script, Not(HasSubstr("--partition")));
  EXPECT_EQ(read_file(slurm / "slurm" / "seeds-1.txt"), "1\n2\n3\n4\n");
  const std::string job = first_job(slurm);
  EXPECT_EQ(read_file(slurm / "slurm" / "jobs"), job + " seeds-1.txt\n");
  EXPECT_EQ(read_file(slurm / "slurm" / "status" / "seed4"), "0 " + job + "_3\n");
  EXPECT_TRUE(fs::exists(slurm / "runs" / "seed4.log"));
}

TEST(MonteCarloSlurm, AFailedTaskIsReportedWithItsSeedAndTheOthersGoOn) {
  TempDir tmp;
  START_LOCAL_CLUSTER(cluster, tmp / "cluster");
  const fs::path out = tmp / "mc";
  // Seed 2's results directory is blocked by a directory that is not ours: that run fails.
  fs::create_directories(out / "runs" / "seed2");
  write_file(out / "runs" / "seed2" / "keep.txt", "not a results directory");
  write_file(out / ".wingman-montecarlo", "");
  const RunResult r = run_wingman(mc_args(out, 3, {"--engine", "slurm"}), tmp.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("run seed 2 failed (exit 2: ")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("not a wingman results directory")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("1 failed)")) << r.output;  // the progress line counts it
  EXPECT_THAT(r.output, HasSubstr("2 runs finished")) << r.output;
  EXPECT_TRUE(fs::exists(out / "runs" / "seed2" / "keep.txt"));
  const auto doc = nlohmann::json::parse(read_file(out / "montecarlo.json"));
  EXPECT_EQ(doc["seeds"], nlohmann::json::array({1, 3}));
  ASSERT_EQ(doc["failed_seeds"].size(), 1u);
  EXPECT_EQ(doc["failed_seeds"][0]["seed"], 2);
}

TEST(MonteCarloSlurm, DetachThenResumeFollowsTheJobAndSubmitsTheRest) {
  TempDir tmp;
  START_LOCAL_CLUSTER(cluster, tmp / "cluster");
  const fs::path out = tmp / "mc";
  // One task at a time, so that the third is still pending when it is cancelled below.
  RunResult r = run_wingman(mc_args(out, 3, {"--engine", "slurm", "--array-limit", "1", "--detach"}), tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string job = first_job(out);
  // Seed 3's task leaves the queue before it ran: on --resume it is neither finished nor queued.
  ASSERT_EQ(std::system(("scancel " + job + "_2").c_str()), 0);
  EXPECT_THAT(squeue_of(job), Not(HasSubstr(job + "_2 "))) << squeue_of(job);
  EXPECT_THAT(r.output, HasSubstr("Slurm job " + job + " runs 3 of the 3 seeds")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("cancel it: scancel " + job)) << r.output;
  EXPECT_FALSE(fs::exists(out / "montecarlo.json"));
  // The exact command to aggregate later: these arguments, without --detach, with --resume.
  const std::string prefix = "follow it and aggregate: ";
  const auto at = r.output.find(prefix);
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string resume = r.output.substr(at + prefix.size(), r.output.find('\n', at) - at - prefix.size());
  EXPECT_THAT(resume, HasSubstr("--engine slurm --array-limit 1 --resume")) << resume;
  EXPECT_THAT(resume, Not(HasSubstr("--detach"))) << resume;
  // Without --resume the directory is refused: its job's tasks would run twice.
  RunResult again = run_wingman(mc_args(out, 3, {"--engine", "slurm"}), tmp.path());
  EXPECT_EQ(again.exit_code, 2) << again.output;
  EXPECT_THAT(again.output, HasSubstr("pass --resume")) << again.output;

  const std::string log = (tmp / "resume.txt").string();
  const int status = std::system(("cd " + quote(tmp.path().string()) + " && " + resume + " > " + quote(log) + " 2>&1").c_str());
  r.output = read_file(log);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("following Slurm job " + job + ": ")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("runs (seed 3)")) << r.output;  // resubmitted alone
  EXPECT_THAT(r.output, HasSubstr("3 runs finished (seeds 1..3), 0 failed")) << r.output;
  EXPECT_EQ(lines_of(read_file(out / "slurm" / "jobs")).size(), 2u);
  EXPECT_EQ(read_file(out / "slurm" / "seeds-2.txt"), "3\n");
  EXPECT_EQ(nlohmann::json::parse(read_file(out / "montecarlo.json"))["seeds"], nlohmann::json::array({1, 2, 3}));
}

TEST(MonteCarloSlurm, CtrlCStopsFollowingAndLeavesTheJobQueued) {
  TempDir tmp;
  START_LOCAL_CLUSTER(cluster, tmp / "cluster");
  const fs::path out = tmp / "mc", log = tmp / "follow.txt";
  std::vector<std::string> args = {kBinary.string()};
  for (const auto& a : mc_args(out, 2, {"--engine", "slurm", "--array-limit", "1"})) args.push_back(a);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
  // Ctrl-C once it follows its job.
  for (int i = 0; i < 300 && read_file(log).find("[montecarlo]") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string output = read_file(log);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), 130) << output;
  const std::string job = first_job(out);
  EXPECT_THAT(output, HasSubstr("interrupted: stopped following")) << output;
  EXPECT_THAT(output, HasSubstr("scancel " + job)) << output;
  EXPECT_THAT(output, HasSubstr("--array-limit 1 --resume")) << output;
  EXPECT_FALSE(fs::exists(out / "montecarlo.json"));
  // The job is still there, its second task waiting for the first.
  EXPECT_THAT(squeue_of(job), HasSubstr(job + "_1 PD")) << squeue_of(job);
  const RunResult r = run_wingman(mc_args(out, 2, {"--engine", "slurm", "--array-limit", "1", "--resume"}), tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("2 runs finished")) << r.output;
  EXPECT_EQ(lines_of(read_file(out / "slurm" / "jobs")).size(), 1u);  // nothing submitted again
}

TEST(MonteCarloSlurm, ARefusedSubmissionExits2WithSbatchsMessage) {
  TempDir tmp;
  START_LOCAL_CLUSTER(cluster, tmp / "cluster");
  const fs::path out = tmp / "mc";
  const RunResult r = run_wingman(mc_args(out, 2, {"--engine", "slurm", "--partition", "nosuchpartition"}), tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("sbatch refused the job")) << r.output;
  EXPECT_THAT(r.output, HasSubstr("Invalid partition name specified")) << r.output;
  EXPECT_FALSE(fs::exists(out / "montecarlo.json"));
  EXPECT_FALSE(fs::exists(out / "slurm" / "jobs"));
  EXPECT_FALSE(fs::exists(out / "slurm" / "array-1.sbatch"));
  EXPECT_FALSE(fs::exists(out / "slurm" / "seeds-1.txt"));
}

// No cluster needed: these fail before anything would be submitted.
TEST(MonteCarloEngines, BadEngineOptionsExit2AndLeaveNoBatch) {
  TempDir tmp;
  const fs::path out = tmp / "mc";
  RunResult r = run_wingman(mc_args(out, 2, {"--engine", "foo"}), tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--engine foo: unknown engine")) << r.output;
  r = run_wingman(mc_args(out, 2, {"--engine", "slurm", "--jobs", "2"}), tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--jobs is for --engine local")) << r.output;
  for (const std::vector<std::string>& slurm_only :
       {std::vector<std::string>{"--partition", "p"}, {"--time", "5"}, {"--mem", "1G"}, {"--array-limit", "2"}, {"--detach"}}) {
    r = run_wingman(mc_args(out, 2, slurm_only), tmp.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(slurm_only[0] + " is for --engine slurm")) << r.output;
  }
  r = run_wingman(mc_args(out, 2, {"--engine", "slurm", "--array-limit", "0"}), tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(out));

  // sbatch not on PATH (an empty directory is the whole PATH here).
  fs::create_directories(tmp / "empty-bin");
  const std::string cmd = "cd " + quote(tmp.path().string()) + " && PATH=" + quote((tmp / "empty-bin").string()) +
                          " " + quote(kBinary.string()) + " montecarlo " + quote(kSmoke.string()) +
                          " --runs 2 --no-plots --engine slurm --out " + quote(out.string()) + " > " +
                          quote((tmp / "nosbatch.txt").string()) + " 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string output = read_file(tmp / "nosbatch.txt");
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << output;
  EXPECT_THAT(output, HasSubstr("sbatch was not found on PATH")) << output;
  EXPECT_FALSE(fs::exists(out / "montecarlo.json"));
  EXPECT_FALSE(fs::exists(out / "slurm" / "jobs"));
}

// A rendered study through Slurm shares one frame cache in the output directory: with the cache
// empty, the first seed's task runs alone and fills it, the others wait for it
// (--dependency=afterany) and read every frame back; the study is the uncached local one's.
TEST(MonteCarloSlurm, TasksShareTheStudysFrameCacheFilledByTheFirstSeed) {
  if (std::string why; !wingman::testing::gl_available(&why)) WINGMAN_NO_GL_CONTEXT(why);
  TempDir tmp;
  START_LOCAL_CLUSTER(cluster, tmp / "cluster");
  const fs::path rendered = kSourceDir / "scenes" / "rendered_smoke.yaml";
  auto args = [&](const fs::path& out, std::vector<std::string> more) {
    std::vector<std::string> a = {"montecarlo", rendered.string(), "--runs", "3", "--frames", "4", "--out",
                                  out.string(), "--no-plots", "--variant", "multi"};
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  const RunResult s = run_wingman(args(tmp / "slurm", {"--engine", "slurm"}), tmp.path());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const RunResult l = run_wingman(args(tmp / "local", {"--no-frame-cache"}), tmp.path());
  ASSERT_EQ(l.exit_code, 0) << l.output;
  EXPECT_EQ(read_file(tmp / "slurm" / "montecarlo.json"), read_file(tmp / "local" / "montecarlo.json"));
  EXPECT_THAT(read_file(tmp / "slurm" / "slurm" / "array-2.sbatch"), HasSubstr("#SBATCH --dependency=afterany:"));
  auto cache_of = [&](const char* seed) {
    return nlohmann::json::parse(read_file(tmp / "slurm" / "runs" / seed / "multi" / "metrics.json"))["frame_cache"];
  };
  EXPECT_EQ(cache_of("seed1")["misses"], 6);  // steps 1-3, two cameras
  for (const char* seed : {"seed2", "seed3"}) {
    EXPECT_EQ(cache_of(seed)["hits"], 6) << seed;
    EXPECT_EQ(cache_of(seed)["misses"], 0) << seed;
  }
}
