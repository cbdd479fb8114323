#include "eval/results_dir.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace wingman::eval {
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

fs::path sibling(const fs::path& final_dir, const char* tag) {
  return final_dir.parent_path() /
         (final_dir.filename().string() + tag + std::to_string(static_cast<long>(::getpid())));
}

void check_replaceable(const fs::path& final_dir) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(final_dir, ec)) && !ResultsDir::is_results_dir(final_dir)) {
    throw std::runtime_error("'" + final_dir.string() +
                             "' exists and is not a wingman results directory (it has no " +
                             ResultsDir::kMarker +
                             " file); refusing to replace it. Choose another output path or "
                             "remove it yourself.");
  }
}

}  // namespace

bool ResultsDir::is_results_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(dir / kMarker, ec);
}

ResultsDir::ResultsDir(fs::path final_dir)
    : final_(normalised(final_dir)), staging_(sibling(final_, ".partial-")) {
  check_replaceable(final_);
  fs::create_directories(final_.parent_path());
  fs::remove_all(staging_);  // stale, from a dead process that had our pid
  fs::create_directory(staging_);
}

ResultsDir::~ResultsDir() {
  if (committed_) return;
  std::error_code ec;  // never throw from a destructor; a leftover is harmless and named
  fs::remove_all(staging_, ec);
}

void ResultsDir::commit() {
  if (committed_) throw std::logic_error("ResultsDir::commit() called twice");
  {
    std::ofstream marker(staging_ / kMarker);
    marker << "wingman results directory; wingman may replace it on a later run\n";
    if (!marker) throw std::runtime_error("cannot write " + (staging_ / kMarker).string());
  }
  check_replaceable(final_);

  // POSIX rename cannot replace a non-empty directory, so move the old one aside first and
  // put it back if the second rename fails.
  std::error_code ec;
  fs::path old;
  if (fs::exists(fs::symlink_status(final_, ec))) {
    old = sibling(final_, ".old-");
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

}  // namespace wingman::eval
