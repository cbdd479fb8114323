// Rendered frames kept on disk, keyed by a hash of everything that determines them, so that runs
// of a study that see the same frames (the same world and truth, different estimator seeds or
// variants) render each once. A key covers the scene's content (every vertex and texture byte: the
// world description, its textures and models), the renderer's code (a hash of its sources made at
// build time), a salt the caller adds (the GL context's description: driver and version), the camera's model (intrinsics, distortion, size) and pose, and
// the lead's pose. The frame stored is the renderer's output before image effects, which the caller
// applies on top, so per-run image noise does not defeat the cache.
//
// An entry is one file, written whole under a temporary name and renamed into place, so a reader
// never sees half of one, whichever process wrote it; a header and payload checksum (XXH64) catch
// an entry damaged since. The directory is bounded: past max_bytes the least recently used
// entries are removed. Several processes may share one directory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "render/renderer.hpp"

namespace wingman::render {

struct FrameKey {
  std::uint64_t hi = 0, lo = 0;
  std::string hex() const;  // 32 hex digits: the entry's file name
  bool operator==(const FrameKey&) const = default;
};

class FrameKeyer {
 public:
  FrameKeyer(const Scene& scene, std::string_view salt);
  FrameKey key(const CameraView& view, const std::optional<LeadPose>& lead) const;

 private:
  std::uint64_t scene_hi_ = 0, scene_lo_ = 0;
  bool timed_ = false;  // the frame depends on its time (drifting cloud shadows)
};

// How an entry's pixels are stored (bench/bench_frame_cache.cpp measures each). Raw is the
// default: on a 1 MP frame of the paper scene it reads back in a quarter of zstd's time for 1.4x
// the bytes (docs/frame_cache.md).
enum class FrameCodec : std::uint32_t { Raw = 0, Zstd = 1 };

struct FrameCacheStats {
  long hits = 0, misses = 0, corrupt = 0, stores = 0, evicted = 0;
  double read_ms = 0, write_ms = 0;  // wall time in load (hits and misses) and store
  std::uint64_t bytes_read = 0, bytes_written = 0;
};

class FrameCache {
 public:
  // Creates `dir` when missing, marking it as a frame cache; throws std::runtime_error naming it
  // when it cannot, or when it holds files and is not a frame cache (eviction removes files).
  FrameCache(std::filesystem::path dir, std::uint64_t max_bytes, FrameCodec codec = FrameCodec::Raw);

  // The frame stored under `key`, or nothing. A damaged entry is reported to the warning
  // callback, removed and counted as a miss: the caller renders and stores it again.
  std::optional<Frame> load(const FrameKey& key);
  // Stores `frame` (CV_8UC3 rgb and CV_32FC1 depth of one size). A failure to write is reported
  // and leaves no entry: the cache only ever saves work.
  void store(const FrameKey& key, const Frame& frame);

  const FrameCacheStats& stats() const { return stats_; }
  const std::filesystem::path& dir() const { return dir_; }
  void on_warning(std::function<void(const std::string&)> warn) { warn_ = std::move(warn); }
  // The entry's path (tests corrupt entries through it).
  std::filesystem::path entry_path(const FrameKey& key) const;

 private:
  void warn(const std::string& what) const;
  void evict_if_full();

  std::filesystem::path dir_;
  std::uint64_t max_bytes_;
  FrameCodec codec_;
  std::uint64_t stored_since_scan_ = 0;
  FrameCacheStats stats_;
  std::function<void(const std::string&)> warn_;
};

// Reads a size such as 20G, 512M or 1048576 (bytes); throws std::invalid_argument otherwise.
std::uint64_t parse_byte_size(std::string_view text);

}  // namespace wingman::render
