// Helpers for the app tests: a self-removing temporary directory, running the real `wingman`
// binary with its output captured, and reading/patching the shipped scenes.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::app::test {

namespace fs = std::filesystem;

inline const fs::path kSourceDir = WINGMAN_SOURCE_DIR;
inline const fs::path kBinary = WINGMAN_BINARY;
inline const fs::path kSmoke = kSourceDir / "scenes" / "smoke.yaml";

// A fresh directory under the system temp directory, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "wingman-app-test-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

inline std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + p.string());
}

// Single-quotes an argument for /bin/sh.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') {
      q += "'\\''";
    } else {
      q += c;
    }
  }
  return q + "'";
}

struct RunResult {
  int exit_code = -1;  // -1 when the process did not exit normally
  std::string output;  // stdout and stderr together
};

// Runs `wingman <args>` in `cwd` with stdout and stderr captured into a file under `capture_dir`.
inline RunResult run_wingman(const std::vector<std::string>& args, const fs::path& capture_dir,
                             const fs::path& cwd = kSourceDir) {
  static int counter = 0;
  const fs::path log = capture_dir / ("wingman-output-" + std::to_string(counter++) + ".txt");
  std::string cmd = "cd ";  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on "lit" + s
  cmd += quote(cwd.string());
  cmd += " && ";
  cmd += quote(kBinary.string());
  for (const auto& a : args) {
    cmd += ' ';
    cmd += quote(a);
  }
  cmd += " > ";
  cmd += quote(log.string());
  cmd += " 2>&1";
  const int status = std::system(cmd.c_str());
  RunResult r;
  if (status != -1 && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  r.output = fs::exists(log) ? read_file(log) : std::string();
  std::error_code ec;
  fs::remove(log, ec);
  return r;
}

// Lines of a text, without their newlines.
inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// Replaces the first occurrence of `from` at or after `start` in `text` (which must be present)
// by `to`, and returns the 1-based line number where it was found (-1 and a test failure if not).
inline int replace_once(std::string& text, const std::string& from, const std::string& to,
                        std::size_t start = 0) {
  const auto pos = text.find(from, start);
  if (pos == std::string::npos) {
    ADD_FAILURE() << "'" << from << "' not found in the scenario";
    return -1;
  }
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
  text.replace(pos, from.size(), to);
  return line;
}

// Replaces the value of the top-level key `key` (a line starting with "key:") by `value` and
// returns the 1-based line number of that key (-1 and a test failure if there is none).
inline int replace_top_level_value(std::string& text, const std::string& key,
                                   const std::string& value) {
  std::size_t pos = text.rfind(key + ":", 0) == 0 ? 0 : text.find("\n" + key + ":");
  if (pos == std::string::npos) {
    ADD_FAILURE() << "no top-level key '" << key << "' in the scenario";
    return -1;
  }
  if (pos != 0) ++pos;
  const auto eol = text.find('\n', pos);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
  text.replace(pos, (eol == std::string::npos ? text.size() : eol) - pos, key + ": " + value);
  return line;
}

}  // namespace wingman::app::test
