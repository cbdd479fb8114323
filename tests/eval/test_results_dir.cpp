#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "eval/results_dir.hpp"
#include "eval_test_support.hpp"

namespace wingman::eval {
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
    ResultsDir rd(final_dir);
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
    ResultsDir rd(final_dir / "");  // a trailing slash names the same directory
    staging = rd.staging();
    touch(staging / "metrics.json", "{}");
    rd.commit();
    EXPECT_TRUE(rd.committed());
  }
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_TRUE(fs::is_regular_file(final_dir / "metrics.json"));
  EXPECT_TRUE(fs::is_regular_file(final_dir / ResultsDir::kMarker));
  EXPECT_TRUE(ResultsDir::is_results_dir(final_dir));
}

TEST(ResultsDir, CommitReplacesPreviousResults) {
  test::TempDir tmp;
  const fs::path final_dir = tmp.path() / "run";
  {
    ResultsDir rd(final_dir);
    touch(rd.staging() / "old_only.txt");
    rd.commit();
  }
  {
    ResultsDir rd(final_dir);
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
    ResultsDir rd(final_dir);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a wingman results directory"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::exists(final_dir / "thesis.tex"));

  // Also when the foreign directory appears during the run.
  const fs::path later = tmp.path() / "later";
  {
    ResultsDir rd(later);
    fs::create_directories(later);
    touch(later / "data.bin");
    EXPECT_THROW(rd.commit(), std::runtime_error);
    EXPECT_FALSE(rd.committed());
  }
  EXPECT_TRUE(fs::exists(later / "data.bin"));
  EXPECT_FALSE(fs::exists(later / ResultsDir::kMarker));

  // A plain file in the way is refused too.
  touch(tmp.path() / "file");
  EXPECT_THROW(ResultsDir(tmp.path() / "file"), std::runtime_error);
}

}  // namespace
}  // namespace wingman::eval
