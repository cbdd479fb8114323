#include "io/results_dir.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace wingman::io {
namespace {

namespace fs = std::filesystem;

fs::path normalised(const fs::path& p) {
  fs::path n = fs::absolute(p).lexically_normal();
  if (n.filename().empty()) n = n.parent_path();  // "out/" names "out"
  const std::string leaf = n.filename().string();
  if (leaf.empty() || leaf == "." || leaf == "..") {
    throw std::runtime_error("'" + p.string() + "' cannot be used as a results directory");
  }
  return n;
}

constexpr const char* kPartial = ".partial-";
constexpr const char* kOld = ".old-";

fs::path sibling(const fs::path& final_dir, const char* tag, long pid = ::getpid()) {
  return final_dir.parent_path() / (final_dir.filename().string() + tag + std::to_string(pid));
}

bool process_alive(long pid) {
  return pid == ::getpid() ? false : (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

// The pid a sibling "<leaf><tag><pid>" names, or -1.
long sibling_pid(const std::string& name, const std::string& prefix) {
  if (name.rfind(prefix, 0) != 0 || name.size() == prefix.size()) return -1;
  const std::string digits = name.substr(prefix.size());
  if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) return -1;
  return std::stol(digits);
}

// A staging directory of process `pid`: left to it while it runs, removed once it is gone (it is
// never complete). Returns the note saying which.
std::string drop_unless_running(const fs::path& dir, long pid) {
  if (process_alive(pid))
    return dir.string() + " is being written by process " + std::to_string(pid) + ", which is still running; left alone";
  std::error_code ec;
  fs::remove_all(dir, ec);
  return "removed " + dir.string() + ", left by process " + std::to_string(pid) + ", which is gone";
}

// Leftovers of processes killed while writing final_dir (SIGKILL, power loss): a staging
// directory is never complete and goes; a moved-aside old directory is a previous result and is
// put back when nothing replaced it.
std::vector<std::string> clean_leftovers(const fs::path& final_dir) {
  std::vector<std::string> notes;
  std::error_code ec;
  const std::string leaf = final_dir.filename().string();
  for (const auto& e : fs::directory_iterator(final_dir.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    for (const char* tag : {kPartial, kOld}) {
      const long pid = sibling_pid(name, leaf + tag);
      if (pid < 0) continue;
      if (tag == kOld && !process_alive(pid) && !fs::exists(fs::symlink_status(final_dir, ec))) {
        fs::rename(e.path(), final_dir, ec);
        notes.push_back("restored " + final_dir.string() + " from " + name + " (process " +
                        std::to_string(pid) + " was killed while replacing it)");
      } else {
        notes.push_back(drop_unless_running(e.path(), pid));
      }
    }
  }
  return notes;
}

void check_replaceable(const fs::path& final_dir, const ResultsDir::Options& o) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(final_dir, ec);
  if (!fs::exists(st)) return;
  // An empty directory (a CI job's `mkdir -p` before the run) holds nothing to lose.
  if (fs::is_directory(st) && fs::is_empty(final_dir, ec) && !ec) return;
  const std::string kind = ResultsDir::kind_of(final_dir);
  if (kind.empty()) {
    throw std::runtime_error("'" + final_dir.string() +
                             "' exists and is not a wingman results directory (it has no " +
                             ResultsDir::kMarker +
                             " file); refusing to replace it. Choose another output path or "
                             "remove it yourself.");
  }
  if (!o.force) {
    auto noun = [](const std::string& k) { return k == "results" ? "wingman results" : "a wingman " + k; };
    throw std::runtime_error("'" + final_dir.string() + "' already holds " + noun(kind) +
                             (kind == o.kind ? "" : " (this command writes " + noun(o.kind) + ")") +
                             "; refusing to replace it. Pass --force to replace it, or choose "
                             "another output path.");
  }
}

}  // namespace

std::vector<std::string> ResultsDir::remove_stale_staging(const fs::path& dir) {
  std::vector<std::string> notes;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const auto at = name.rfind(kPartial);
    if (at == std::string::npos || at == 0) continue;
    const long pid = sibling_pid(name, name.substr(0, at) + kPartial);
    if (pid < 0) continue;
    notes.push_back(drop_unless_running(e.path(), pid));
  }
  return notes;
}

bool ResultsDir::is_results_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(dir / kMarker, ec);
}

std::string ResultsDir::kind_of(const fs::path& dir) {
  if (!is_results_dir(dir)) return "";
  std::ifstream in(dir / kMarker);
  std::string wingman, kind;
  in >> wingman >> kind;  // "wingman <kind> directory ..."
  if (kind == "dataset" || fs::exists(dir / "dataset.yaml")) return "dataset";
  return "results";
}

ResultsDir::ResultsDir(fs::path final_dir, Options options)
    : final_(normalised(final_dir)), staging_(sibling(final_, kPartial)), options_(std::move(options)) {
  fs::create_directories(final_.parent_path());
  notes_ = clean_leftovers(final_);
  check_replaceable(final_, options_);
  fs::remove_all(staging_);  // stale, from a dead process that had our pid
  fs::create_directory(staging_);
}

ResultsDir::ResultsDir(fs::path final_dir) : ResultsDir(std::move(final_dir), Options{}) {}

ResultsDir::~ResultsDir() {
  if (committed_) return;
  std::error_code ec;  // never throw from a destructor; a leftover is named by the next run
  fs::remove_all(staging_, ec);
}

void ResultsDir::commit() {
  if (committed_) throw std::logic_error("ResultsDir::commit() called twice");
  {
    std::ofstream marker(staging_ / kMarker);
    marker << "wingman " << options_.kind
           << " directory; wingman replaces it only when asked to (--force)\n";
    if (!marker.flush()) throw std::runtime_error("cannot write " + (staging_ / kMarker).string());
  }
  check_replaceable(final_, options_);

  // POSIX rename cannot replace a non-empty directory, so move the old one aside first and
  // put it back if the second rename fails.
  std::error_code ec;
  fs::path old;
  if (fs::exists(fs::symlink_status(final_, ec))) {
    old = sibling(final_, kOld);
    fs::remove_all(old);
    fs::rename(final_, old);
  }
  try {
    fs::rename(staging_, final_);
  } catch (...) {
    if (!old.empty()) fs::rename(old, final_, ec);
    throw;
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, ec);
}

}  // namespace wingman::io
