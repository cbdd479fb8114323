// `wingman export <dataset> --bag FILE`: a dataset as a ROS 1 bag (datasets/bag/bag_export.hpp,
// docs/ros_bag.md). The bag is written to "<FILE>.partial-<pid>" beside FILE and renamed when
// complete, so an export that fails or is interrupted leaves nothing under either name.
#include "app/cli/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <signal.h>
#include <fmt/core.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "datasets/bag/bag_export.hpp"
#include "datasets/dataset.hpp"

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

struct ExportOptions {
  std::string dataset;
  std::string bag;
  std::string compression = "none";
  bool force = false;
  bool quiet = false;
};

// The temporary sibling of the target file; removed on destruction unless committed.
class StagedFile {
 public:
  StagedFile(fs::path target, bool force) : target_(std::move(target)) {
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(target_, ec);
    if (fs::is_directory(st)) throw io::UsageError(fmt::format("'{}' is a directory, not a bag file", target_.string()));
    if (fs::exists(st) && !force)
      throw io::UsageError(fmt::format("'{}' exists; pass --force to replace it", target_.string()));
    const fs::path dir = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
      throw io::UsageError(fmt::format("cannot write '{}': '{}' {}", target_.string(), dir.string(),
                                   fs::exists(dir, ec) ? "is not a directory" : "does not exist"));
    remove_stale(dir);
    tmp_ = target_.string() + ".partial-" + std::to_string(::getpid());
    const int fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw io::UsageError(fmt::format("cannot write '{}': {}", target_.string(), std::strerror(errno)));
    ::close(fd);
  }
  ~StagedFile() {
    std::error_code ec;
    if (!committed_) fs::remove(tmp_, ec);
  }
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  const fs::path& path() const { return tmp_; }
  void commit() {
    if (::rename(tmp_.c_str(), target_.c_str()) != 0)
      throw std::runtime_error(fmt::format("cannot write '{}': rename: {}", target_.string(), std::strerror(errno)));
    committed_ = true;
  }

 private:
  // "<name>.partial-<pid>" files a killed export (SIGKILL) left beside the target: removed when
  // their process is gone, as the staging directories of io::ResultsDir are.
  void remove_stale(const fs::path& dir) const {
    const std::string prefix = target_.filename().string() + ".partial-";
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      if (name.rfind(prefix, 0) != 0) continue;
      const std::string pid = name.substr(prefix.size());
      if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
      if (::kill(static_cast<pid_t>(std::stol(pid)), 0) == 0 || errno != ESRCH) continue;
      if (fs::remove(e.path(), ec)) fmt::print(stderr, "removed {}, left by a killed export\n", e.path().string());
    }
  }

  fs::path target_, tmp_;
  bool committed_ = false;
};

int export_command(const ExportOptions& o) {
  static const std::map<std::string, datasets::BagCompression> kCompression = {
      {"none", datasets::BagCompression::None},
      {"lz4", datasets::BagCompression::Lz4},
      {"bz2", datasets::BagCompression::Bz2}};
  StagedFile staged(o.bag, o.force);  // refuses before any work
  const datasets::Dataset ds = datasets::read_dataset(o.dataset);

  io::ProgressLine progress(fmt::format("[export {}]", ds.info.scenario), o.quiet);
  datasets::BagExportOptions options;
  options.compression = kCompression.at(o.compression);
  options.progress = [&](std::size_t done, std::size_t total) {
    io::throw_if_interrupted();  // unwinds through the staged file: nothing half-written stays
    if (done % 64 == 0 || done == total) progress.update(static_cast<int>(done), static_cast<int>(total), "samples");
  };
  const auto start = std::chrono::steady_clock::now();
  const datasets::BagExportSummary summary = datasets::write_bag(ds, staged.path(), options);
  staged.commit();
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!o.quiet) {
    for (const auto& [topic, count] : summary.messages) fmt::print("{:>8}  {}\n", count, topic);
    fmt::print("bag: {} ({} messages, {:.1f} MB, {:.2f} s)\n", o.bag, summary.total(),
               static_cast<double>(fs::file_size(o.bag)) / 1e6, seconds);
  }
  return 0;
}

}  // namespace

Subcommand add_export(CLI::App& parent) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = parent.add_subcommand(
      "export", "Write a dataset of `wingman render` as a ROS 1 bag: images, depth, camera_info, "
                "IMU, ground truth on /tf and as odometry, sensor samples (docs/ros_bag.md)");
  cmd->add_option("dataset", o->dataset, "Dataset directory")->required();
  cmd->add_option("--bag", o->bag, "The bag file to write")->required();
  cmd->add_option("--compression", o->compression, "Chunk compression of the bag")
      ->check(CLI::IsMember({"none", "lz4", "bz2"}))
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "Replace an existing bag file");
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  return {cmd, [o] { return export_command(*o); }};
}

}  // namespace wingman::app
