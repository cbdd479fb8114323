// A file written by io::write_file_atomic is whole or absent: a full disk (here a file-size limit,
// which fails the write the same way) is an error naming the file, and the previous content stays.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

#include "io/atomic_file.hpp"
#include "io/io_test_support.hpp"

namespace wingman::io {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(AtomicFile, WritesAndReplacesWholeFiles) {
  test::TempDir tmp;
  const fs::path p = tmp.path() / "sub" / "montecarlo.json";
  io::write_file_atomic(p, "first\n");
  EXPECT_EQ(slurp(p), "first\n");
  io::write_file_atomic(p, "second\n");
  EXPECT_EQ(slurp(p), "second\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(p.parent_path())) ++entries;
  EXPECT_EQ(entries, 1);  // no temporary left beside it
}

TEST(AtomicFile, AFullDiskIsAnErrorAndKeepsThePreviousFile) {
  test::TempDir tmp;
  const fs::path p = tmp.path() / "montecarlo.json";
  io::write_file_atomic(p, "previous\n");
  // In a child: a 4 KiB file-size limit makes the 64 KiB write fail as a full disk would.
  const pid_t pid = fork();
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit lim{4096, 4096};
    setrlimit(RLIMIT_FSIZE, &lim);
    try {
      io::write_file_atomic(p, std::string(65536, 'x'));
    } catch (const std::runtime_error& e) {
      _exit(std::string(e.what()).find(p.string()) != std::string::npos ? 0 : 3);
    }
    _exit(4);  // no error: the failure went unnoticed
  }
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 0) << "3: the message does not name the file; 4: no error";
  EXPECT_EQ(slurp(p), "previous\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(tmp.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

}  // namespace
}  // namespace wingman::io
