#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "io/results_dir.hpp"
#include "io/io_test_support.hpp"

namespace wingman::io {
namespace {

namespace fs = std::filesystem;

void touch(const fs::path& p, const std::string& text = "x") {
  std::ofstream(p) << text;
}

TEST(ResultsDir, UncommittedStagingIsRemoved) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "nested" / "run1";
  fs::path staging;
  {
    io::ResultsDir rd(final_dir);
    staging = rd.staging();
    EXPECT_EQ(staging.parent_path(), fs::absolute(final_dir).parent_path());
    EXPECT_EQ(staging.filename().string().rfind("run1.partial-", 0), 0u) << staging;
    ASSERT_TRUE(fs::is_directory(staging));  // parents were created
    touch(staging / "metrics.json");
  }
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(final_dir));
}

TEST(ResultsDir, CommitMovesIntoPlaceWithMarker) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "run";
  fs::path staging;
  {
    io::ResultsDir rd(final_dir / "");  // a trailing slash names the same directory
    staging = rd.staging();
    touch(staging / "metrics.json", "{}");
    rd.commit();
    EXPECT_TRUE(rd.committed());
  }
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_TRUE(fs::is_regular_file(final_dir / "metrics.json"));
  EXPECT_TRUE(fs::is_regular_file(final_dir / io::ResultsDir::kMarker));
  EXPECT_TRUE(io::ResultsDir::is_results_dir(final_dir));
}

TEST(ResultsDir, ExistingResultsAreRefusedWithoutForce) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "run";
  {
    io::ResultsDir rd(final_dir);
    fs::create_directories(rd.staging() / "multi");
    touch(rd.staging() / "multi" / "metrics.json");
    rd.commit();
  }
  try {
    io::ResultsDir rd(final_dir);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--force"), std::string::npos) << e.what();
  }
  try {  // a dataset command names what the directory holds
    io::ResultsDir rd(final_dir, {"dataset", false});
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("already holds wingman results"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(final_dir / "multi" / "metrics.json"));
  EXPECT_EQ(io::ResultsDir::kind_of(final_dir), "results");
  // Appearing during the run is refused at commit, and the existing one is kept.
  const fs::path later = tmp.path() / "later";
  {
    io::ResultsDir rd(later, {"dataset", false});
    {
      io::ResultsDir other(later);
      touch(other.staging() / "first.txt");
      other.commit();
    }
    EXPECT_THROW(rd.commit(), std::runtime_error);
  }
  EXPECT_TRUE(fs::exists(later / "first.txt"));
}

// The pid of a process that has exited (and been reaped): what a killed writer leaves behind.
pid_t a_dead_pid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, nullptr, 0);
  return pid;
}

TEST(ResultsDir, AnExistingEmptyDirectoryIsFilledWithoutForce) {
  io::test::TempDir tmp;
  const fs::path out = tmp.path() / "made_by_ci";
  fs::create_directories(out);
  {
    ResultsDir r(out);
    std::ofstream(r.staging() / "metrics.json") << "{}";
    r.commit();
  }
  EXPECT_TRUE(fs::exists(out / "metrics.json"));
  EXPECT_TRUE(ResultsDir::is_results_dir(out));
}

TEST(ResultsDir, AnExistingDirectoryWithAFileOfTheUsersIsRefused) {
  io::test::TempDir tmp;
  const fs::path out = tmp.path() / "mine";
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "mine";
  EXPECT_THROW(ResultsDir(out, {"results", true}), std::runtime_error);
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
}

TEST(ResultsDir, StagingLeftByAKilledProcessIsRemovedAndNamed) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "run";
  const pid_t dead = a_dead_pid();
  const fs::path stale = tmp.path() / ("run.partial-" + std::to_string(dead));
  const fs::path live = tmp.path() / ("run.partial-" + std::to_string(getppid()));
  const fs::path unrelated = tmp.path() / "runs.partial-1";
  for (const auto& d : {stale, live, unrelated}) fs::create_directories(d), touch(d / "metrics.json");
  io::ResultsDir rd(final_dir);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));       // its process is still running
  EXPECT_TRUE(fs::exists(unrelated));  // another target's
  ASSERT_EQ(rd.notes().size(), 2u);
  std::string all = rd.notes()[0] + "\n" + rd.notes()[1];
  EXPECT_NE(all.find("removed " + stale.string()), std::string::npos) << all;
  EXPECT_NE(all.find("still running"), std::string::npos) << all;
}

TEST(ResultsDir, PreviousResultMovedAsideByAKilledProcessIsRestored) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "run";
  const pid_t dead = a_dead_pid();
  const fs::path old = tmp.path() / ("run.old-" + std::to_string(dead));
  fs::create_directories(old);
  touch(old / io::ResultsDir::kMarker, "wingman results directory\n");
  touch(old / "metrics.json");
  EXPECT_THROW(io::ResultsDir rd(final_dir), std::runtime_error);  // restored, so now it exists
  EXPECT_TRUE(fs::exists(final_dir / "metrics.json"));
  EXPECT_FALSE(fs::exists(old));
}

TEST(ResultsDir, ForceReplacesPreviousResults) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "run";
  {
    io::ResultsDir rd(final_dir);
    touch(rd.staging() / "old_only.txt");
    rd.commit();
  }
  {
    io::ResultsDir rd(final_dir, {"results", true});
    touch(rd.staging() / "new.txt");
    rd.commit();
  }
  EXPECT_TRUE(fs::exists(final_dir / "new.txt"));
  EXPECT_FALSE(fs::exists(final_dir / "old_only.txt"));
  // Nothing is left beside it: no staging, no moved-aside old directory.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(tmp.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(ResultsDir, RefusesToReplaceForeignDirectory) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "precious";
  fs::create_directories(final_dir);
  touch(final_dir / "thesis.tex");
  try {
    io::ResultsDir rd(final_dir);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a wingman results directory"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::exists(final_dir / "thesis.tex"));

  // Also when the foreign directory appears during the run, even with force.
  const fs::path later = tmp.path() / "later";
  {
    io::ResultsDir rd(later, {"results", true});
    fs::create_directories(later);
    touch(later / "data.bin");
    EXPECT_THROW(rd.commit(), std::runtime_error);
    EXPECT_FALSE(rd.committed());
  }
  EXPECT_TRUE(fs::exists(later / "data.bin"));
  EXPECT_FALSE(fs::exists(later / io::ResultsDir::kMarker));

  // A plain file in the way is refused too.
  touch(tmp.path() / "file");
  EXPECT_THROW(io::ResultsDir(tmp.path() / "file"), std::runtime_error);
}

}  // namespace
}  // namespace wingman::io
