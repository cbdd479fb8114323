// The Slurm engine's pieces that need no cluster: the array script, reading squeue's answer, and
// the job record (tests/app/batch/test_montecarlo_slurm.cpp runs the engine on a real one).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/batch/slurm_queue.hpp"
#include "app/batch/slurm_script.hpp"
#include "app/cli/subcommand.hpp"
#include "app/app_test_support.hpp"

using namespace wingman::app;
namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(SlurmScript, RunsTheLocalWorkersCommandWithTheSeedFromItsTask) {
  const ArrayJob job{"/shared/mc", 2, {5, 6, 9}, "wingman-smoke", "/opt/bin/wingman", "/home/me", ""};
  RunSpec spec{"/home/me/scenes/it's.yaml", {"multi"}, {}, {}};
  spec.limit.frames = 40;
  const SlurmOptions options{"gpu", "1:00:00", "2G", 2, false};
  const std::string s = array_script(job, spec, options);
  EXPECT_EQ(s.rfind("#!/bin/bash\n", 0), 0u);
  for (const char* line : {"#SBATCH --array=0-2%2\n", "#SBATCH --partition=gpu\n", "#SBATCH --time=1:00:00\n",
                           "#SBATCH --mem=2G\n", "#SBATCH --output=/shared/mc/slurm/logs/%A_%a.out\n",
                           "#SBATCH --chdir=/home/me\n", "#SBATCH --job-name=wingman-smoke\n"})
    EXPECT_THAT(s, HasSubstr(line));
  EXPECT_THAT(s, HasSubstr("p\" '/shared/mc/slurm/seeds-2.txt')"));
  // run_arguments, quoted, with "$seed" in place of the seed.
  EXPECT_THAT(s, HasSubstr("'/opt/bin/wingman' 'run' '/home/me/scenes/it'\\''s.yaml' '--seed' \"$seed\" '--out' "
                           "'/shared/mc/runs/seed'\"$seed\" '--no-plots' '-q' '--variant' 'multi' '--frames' '40' "
                           "> '/shared/mc/runs/seed'\"$seed\"'.log' 2>&1\n"));
  EXPECT_THAT(s, HasSubstr("status='/shared/mc/slurm/status/seed'\"$seed\"\n"));
  EXPECT_THAT(s, HasSubstr("mv -f \"$status.tmp.$SLURM_JOB_ID\" \"$status\""));
  EXPECT_THAT(s, Not(HasSubstr("\x1f")));
  // A rendered study's tasks share its frame cache, under the shared output directory.
  RunSpec cached = spec;
  cached.frame_cache = {"/shared/mc/frame_cache", 1ull << 30};
  EXPECT_THAT(array_script(job, cached, options),
              HasSubstr("'--frames' '40' '--frame-cache' '/shared/mc/frame_cache' '--frame-cache-size' '1073741824' >"));
  // A submission that waits for another job (the one filling an empty frame cache).
  ArrayJob after = job;
  after.after = "41";
  EXPECT_THAT(array_script(after, spec, options), HasSubstr("#SBATCH --dependency=afterany:41\n"));
  EXPECT_THAT(array_script(job, spec, options), Not(HasSubstr("--dependency")));
  // Options left out are the cluster's defaults.
  EXPECT_THAT(array_script(job, spec, {}), Not(HasSubstr("--partition")));
  EXPECT_THAT(array_script(job, spec, {}), HasSubstr("#SBATCH --array=0-2\n"));
}

TEST(SlurmQueue, ReadsTheTasksOfItsJobFromSqueue) {
  const auto tasks = parse_squeue("41_0 R\n41_3 PD\n410_1 R\n41_[4-7%2] PD\n42 R\n", "41");
  ASSERT_EQ(tasks.size(), 2u);
  EXPECT_EQ(tasks.at(0), "R");
  EXPECT_EQ(tasks.at(3), "PD");
}

TEST(SlurmQueue, RecordsJobsAndReadsThemBack) {
  test::TempDir tmp;
  const fs::path out = tmp.path();
  EXPECT_TRUE(read_jobs(out).empty());
  fs::create_directories(out / "slurm");
  test::write_file(out / "slurm" / "seeds-1.txt", "3\n4\n");
  test::write_file(out / "slurm" / "seeds-2.txt", "7\n");
  record_job(out, "12", 1);
  record_job(out, "15", 2);
  EXPECT_EQ(test::read_file(out / "slurm" / "jobs"), "12 seeds-1.txt\n15 seeds-2.txt\n");
  const auto jobs = read_jobs(out);
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[0].id, "12");
  EXPECT_EQ(jobs[0].seeds, (std::vector<std::uint64_t>{3, 4}));
  EXPECT_EQ(jobs[1].seeds, (std::vector<std::uint64_t>{7}));
  test::write_file(out / "slurm" / "jobs", "12 ../elsewhere.txt\n");
  EXPECT_THROW(read_jobs(out), wingman::io::UsageError);

  fs::create_directories(out / "slurm" / "status");
  test::write_file(out / "slurm" / "status" / "seed3", "0 12_0\n");
  test::write_file(out / "slurm" / "status" / "seed4", "1 12_1\n");
  test::write_file(out / "slurm" / "status" / "seed7.tmp.16", "0 15_0\n");
  const auto st = read_statuses(out);
  ASSERT_EQ(st.size(), 2u);
  EXPECT_EQ(st.at(3).exit_code, 0);
  EXPECT_EQ(st.at(4).exit_code, 1);
  EXPECT_EQ(st.at(4).task, "12_1");
}
