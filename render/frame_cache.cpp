#include "render/frame_cache.hpp"

#include "render/source_hash.hpp"  // generated: cmake/source_hash.cmake

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace wingman::render {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

constexpr char kMagic[8] = {'W', 'M', 'F', 'R', 'A', 'M', 'E', '1'};
constexpr const char* kMarkerFile = ".wingman-frame-cache";
// zstd's fastest level: even so a 1 MP frame costs about 4.5x a raw one's CPU to store and 9x to
// read back, for 30 % fewer bytes (bench/bench_frame_cache.cpp, docs/frame_cache.md).
constexpr int kZstdLevel = 1;

struct Header {
  char magic[8];
  std::uint64_t key_hi, key_lo;
  std::int32_t width, height;
  std::uint32_t codec, reserved;
  std::uint64_t rgb_bytes, depth_bytes;  // as stored
  std::uint64_t payload_hash;            // XXH3-64 of the stored bytes
  std::uint64_t header_hash;             // XXH3-64 of everything above
};

std::uint64_t header_hash(const Header& h) { return XXH3_64bits(&h, offsetof(Header, header_hash)); }

void hash_bytes(XXH3_state_t* s, const void* data, std::size_t n) {
  const std::uint64_t size = n;
  XXH3_128bits_update(s, &size, sizeof size);  // sizes first: no two contents hash alike by shifting
  if (n) XXH3_128bits_update(s, data, n);
}

template <typename T>
void hash_vector(XXH3_state_t* s, const std::vector<T>& v) { hash_bytes(s, v.data(), v.size() * sizeof(T)); }

void hash_mat(XXH3_state_t* s, const cv::Mat& m) {
  const std::int32_t shape[3] = {m.rows, m.cols, m.type()};
  hash_bytes(s, shape, sizeof shape);
  for (int r = 0; r < m.rows; ++r) hash_bytes(s, m.ptr(r), m.cols * m.elemSize());
}

void hash_doubles(XXH3_state_t* s, std::initializer_list<double> xs) {
  const std::vector<double> v(xs);
  hash_vector(s, v);
}

// Depth's float bytes regrouped by significance (all first bytes, then all second bytes, ...):
// neighbouring depths share their high bytes, which zstd then finds; plain floats barely compress.
void shuffle4(const std::uint8_t* in, std::uint8_t* out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    for (int b = 0; b < 4; ++b) out[b * n + i] = in[4 * i + b];
}
void unshuffle4(const std::uint8_t* in, std::uint8_t* out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    for (int b = 0; b < 4; ++b) out[4 * i + b] = in[b * n + i];
}

std::vector<std::uint8_t> zstd_compress(const void* data, std::size_t n) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(n));
  const std::size_t r = ZSTD_compress(out.data(), out.size(), data, n, kZstdLevel);
  if (ZSTD_isError(r)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(r));
  out.resize(r);
  return out;
}

bool zstd_decompress(const std::uint8_t* in, std::size_t n, void* out, std::size_t expect) {
  const std::size_t r = ZSTD_decompress(out, expect, in, n);
  return !ZSTD_isError(r) && r == expect;
}

// A zstd entry's pixels from its payload, or an empty frame when they do not decode.
Frame decode_zstd(const Header& h, const std::uint8_t* payload) {
  Frame f;
  f.rgb.create(h.height, h.width, CV_8UC3);
  f.depth.create(h.height, h.width, CV_32FC1);
  const std::size_t rgb_n = f.rgb.total() * 3, depth_n = f.depth.total() * 4;
  std::vector<std::uint8_t> shuffled(depth_n);
  if (!zstd_decompress(payload, h.rgb_bytes, f.rgb.data, rgb_n) ||
      !zstd_decompress(payload + h.rgb_bytes, h.depth_bytes, shuffled.data(), depth_n))
    return {};
  unshuffle4(shuffled.data(), f.depth.data, f.depth.total());
  return f;
}

std::uint64_t payload_hash(const void* a, std::size_t na, const void* b, std::size_t nb) {
  XXH3_state_t* st = XXH3_createState();
  XXH3_64bits_reset(st);
  XXH3_64bits_update(st, a, na);
  XXH3_64bits_update(st, b, nb);
  const std::uint64_t h = XXH3_64bits_digest(st);
  XXH3_freeState(st);
  return h;
}

constexpr const char* kMissing = "missing";

// Reads the entry at `path` into `f` (raw pixels straight into the frame's buffers): nullptr when
// it is whole, kMissing when there is none, else what is wrong with it.
const char* read_entry(const fs::path& path, const FrameKey& key, Frame& f, std::uint64_t& bytes) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) return kMissing;
  struct stat st {};
  if (::fstat(::fileno(file.get()), &st) != 0) return kMissing;
  bytes = static_cast<std::uint64_t>(st.st_size);
  Header h;
  if (bytes < sizeof h || std::fread(&h, sizeof h, 1, file.get()) != 1) return "shorter than its header";
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 || h.header_hash != header_hash(h)) return "bad header";
  if (h.key_hi != key.hi || h.key_lo != key.lo) return "holds another key";
  const std::uint64_t pixels = static_cast<std::uint64_t>(h.width) * static_cast<std::uint64_t>(h.height);
  if (h.width <= 0 || h.height <= 0 || bytes != sizeof h + h.rgb_bytes + h.depth_bytes) return "wrong size";
  if (h.codec == static_cast<std::uint32_t>(FrameCodec::Raw)) {
    if (h.rgb_bytes != 3 * pixels || h.depth_bytes != 4 * pixels) return "wrong size";
    f.rgb.create(h.height, h.width, CV_8UC3);
    f.depth.create(h.height, h.width, CV_32FC1);
    if (std::fread(f.rgb.data, 1, h.rgb_bytes, file.get()) != h.rgb_bytes ||
        std::fread(f.depth.data, 1, h.depth_bytes, file.get()) != h.depth_bytes)
      return "wrong size";
    if (payload_hash(f.rgb.data, h.rgb_bytes, f.depth.data, h.depth_bytes) != h.payload_hash) return "checksum mismatch";
    return nullptr;
  }
  if (h.codec != static_cast<std::uint32_t>(FrameCodec::Zstd)) return "unknown codec";
  std::vector<std::uint8_t> payload(h.rgb_bytes + h.depth_bytes);
  if (std::fread(payload.data(), 1, payload.size(), file.get()) != payload.size()) return "wrong size";
  if (XXH3_64bits(payload.data(), payload.size()) != h.payload_hash) return "checksum mismatch";
  f = decode_zstd(h, payload.data());
  return f.rgb.empty() ? "pixels do not decode" : nullptr;
}

}  // namespace

std::string FrameKey::hex() const { return fmt::format("{:016x}{:016x}", hi, lo); }

FrameKeyer::FrameKeyer(const Scene& scene, std::string_view salt) {
  std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> s(XXH3_createState(), &XXH3_freeState);
  XXH3_128bits_reset(s.get());
  const std::string_view code = kRenderSourceHash;
  hash_bytes(s.get(), code.data(), code.size());
  hash_bytes(s.get(), salt.data(), salt.size());
  for (const Material& m : scene.materials) {
    hash_mat(s.get(), m.texture);
    hash_doubles(s.get(), {double(m.repeat), double(m.mipmaps), m.anisotropy, double(m.trilinear), double(m.unlit)});
    if (m.stochastic_cell > 0)  // hashed only when on
      hash_doubles(s.get(), {m.stochastic_cell, m.blend_sharpness, double(m.stochastic_seed), double(m.bake)});
  }
  for (const auto* meshes : {&scene.static_meshes, &scene.lead_meshes, &scene.body_meshes}) {
    hash_doubles(s.get(), {double(meshes->size())});
    for (const Mesh& m : *meshes) {
      hash_vector(s.get(), m.positions);
      hash_vector(s.get(), m.normals);
      hash_vector(s.get(), m.uvs);
      hash_vector(s.get(), m.colours);
      hash_vector(s.get(), m.indices);
      hash_doubles(s.get(), {double(m.material)});
    }
  }
  const auto& l = scene.light;
  hash_doubles(s.get(), {l.direction.x(), l.direction.y(), l.direction.z(), l.ambient, l.diffuse, scene.sky.x(),
                         scene.sky.y(), scene.sky.z(), scene.near, scene.far, double(scene.msaa)});
  if (l.shadows) hash_doubles(s.get(), {1.0, double(l.shadow_map)});  // hashed only when on
  if (l.skylight.model != sim::SkylightSpec::Model::Constant)
    hash_doubles(s.get(), {2.0, l.skylight.ground_albedo, l.skylight.aerosol_depth});
  timed_ = !scene.clouds.empty();
  if (timed_) {
    const sim::CloudSpec& c = l.clouds;
    hash_mat(s.get(), scene.clouds);
    hash_doubles(s.get(), {c.scale, c.height, c.wind.x(), c.wind.y(), c.transmission});
  }
  const XXH128_hash_t h = XXH3_128bits_digest(s.get());
  scene_hi_ = h.high64;
  scene_lo_ = h.low64;
}

FrameKey FrameKeyer::key(const CameraView& view, const std::optional<LeadPose>& lead) const {
  const geometry::PinholeCamera& c = view.camera;
  const geometry::Distortion& d = c.distortion();
  const Eigen::Matrix3d& R = view.pose.R_CW;
  const Eigen::Vector3d& p = view.pose.position;
  const std::uint64_t scene[2] = {scene_hi_, scene_lo_};
  std::vector<double> v = {c.fx(), c.fy(), c.cx(), c.cy(), double(c.width()), double(c.height()),
                           d.k1,   d.k2,   d.p1,   d.p2,   d.k3};
  v.insert(v.end(), R.data(), R.data() + 9);
  v.insert(v.end(), p.data(), p.data() + 3);
  if (lead) v.insert(v.end(), {1.0, lead->position.x(), lead->position.y(), lead->position.z(), lead->yaw});
  for (const LeadPose& b : view.bodies) v.insert(v.end(), {2.0, b.position.x(), b.position.y(), b.position.z(), b.yaw});
  for (const auto& [cam, pose] : view.shadow_views) {  // they bound the sun's shadow map
    v.insert(v.end(), {3.0, cam.fx(), cam.fy(), cam.cx(), cam.cy(), double(cam.width()), double(cam.height())});
    v.insert(v.end(), pose.R_CW.data(), pose.R_CW.data() + 9);
    v.insert(v.end(), pose.position.data(), pose.position.data() + 3);
  }
  if (timed_) v.push_back(view.time);
  std::vector<std::uint8_t> bytes(sizeof scene + v.size() * sizeof(double));
  std::memcpy(bytes.data(), scene, sizeof scene);
  std::memcpy(bytes.data() + sizeof scene, v.data(), v.size() * sizeof(double));
  const XXH128_hash_t h = XXH3_128bits(bytes.data(), bytes.size());
  return {h.high64, h.low64};
}

FrameCache::FrameCache(fs::path dir, std::uint64_t max_bytes, FrameCodec codec)
    : dir_(std::move(dir)), max_bytes_(max_bytes), codec_(codec) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_))
    throw std::runtime_error(fmt::format("{}: cannot create the frame cache directory: {}", dir_.string(),
                                         ec ? ec.message() : "not a directory"));
  if (::access(dir_.c_str(), W_OK) != 0)
    throw std::runtime_error(fmt::format("{}: the frame cache directory is not writable", dir_.string()));
  // A directory of someone else's files is never taken over (the cache removes files as it evicts).
  const fs::path marker = dir_ / kMarkerFile;
  if (!fs::exists(marker)) {
    if (!fs::is_empty(dir_, ec))
      throw std::runtime_error(fmt::format("{}: not empty and not a wingman frame cache (no {}); choose a new or "
                                           "empty directory", dir_.string(), kMarkerFile));
    std::ofstream(marker) << "wingman frame cache: render/frame_cache.hpp, docs/frame_cache.md\n";
  }
}

fs::path FrameCache::entry_path(const FrameKey& key) const {
  const std::string hex = key.hex();
  return dir_ / hex.substr(0, 2) / (hex + ".frame");
}

void FrameCache::warn(const std::string& what) const {
  if (warn_) warn_(what);
}

std::optional<Frame> FrameCache::load(const FrameKey& key) {
  const auto t0 = Clock::now();
  const fs::path path = entry_path(key);
  Frame f;
  std::uint64_t bytes = 0;
  const char* why = read_entry(path, key, f, bytes);
  if (why) {
    if (why != kMissing) {
      ++stats_.corrupt;
      warn(fmt::format("{}: damaged frame cache entry ({}); removed, the frame is rendered again", path.string(), why));
      std::error_code ec;
      fs::remove(path, ec);
    }
    ++stats_.misses;
    stats_.read_ms += ms_since(t0);
    return std::nullopt;
  }
  std::error_code ec;
  fs::last_write_time(path, fs::file_time_type::clock::now(), ec);  // recently used: evicted last
  ++stats_.hits;
  stats_.bytes_read += bytes;
  stats_.read_ms += ms_since(t0);
  return f;
}

void FrameCache::store(const FrameKey& key, const Frame& frame) {
  const auto t0 = Clock::now();
  if (frame.rgb.type() != CV_8UC3 || frame.depth.type() != CV_32FC1 || frame.rgb.size() != frame.depth.size())
    throw std::invalid_argument("FrameCache::store: a frame is CV_8UC3 colour and CV_32FC1 depth of one size");
  const cv::Mat rgb = frame.rgb.isContinuous() ? frame.rgb : frame.rgb.clone();
  const cv::Mat depth = frame.depth.isContinuous() ? frame.depth : frame.depth.clone();
  const std::size_t rgb_n = rgb.total() * 3, depth_n = depth.total() * 4;
  std::vector<std::uint8_t> rgb_z, depth_z;
  const std::uint8_t *rgb_p = rgb.data, *depth_p = depth.data;
  std::size_t rgb_s = rgb_n, depth_s = depth_n;
  if (codec_ == FrameCodec::Zstd) {
    std::vector<std::uint8_t> shuffled(depth_n);
    shuffle4(depth.data, shuffled.data(), depth.total());
    rgb_z = zstd_compress(rgb.data, rgb_n);
    depth_z = zstd_compress(shuffled.data(), depth_n);
    rgb_p = rgb_z.data(), depth_p = depth_z.data();
    rgb_s = rgb_z.size(), depth_s = depth_z.size();
  }
  Header h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.key_hi = key.hi, h.key_lo = key.lo;
  h.width = rgb.cols, h.height = rgb.rows;
  h.codec = static_cast<std::uint32_t>(codec_);
  h.rgb_bytes = rgb_s, h.depth_bytes = depth_s;
  h.payload_hash = payload_hash(rgb_p, rgb_s, depth_p, depth_s);
  h.header_hash = header_hash(h);

  const fs::path path = entry_path(key);
  static std::atomic<std::uint64_t> counter{0};
  const fs::path tmp = path.parent_path() / fmt::format(".tmp-{}-{}-{}", key.hex(), ::getpid(), counter++);
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  bool ok = false;
  if (FILE* f = std::fopen(tmp.c_str(), "wb")) {
    ok = std::fwrite(&h, sizeof h, 1, f) == 1 && std::fwrite(rgb_p, 1, rgb_s, f) == rgb_s &&
         std::fwrite(depth_p, 1, depth_s, f) == depth_s;
    ok = (std::fclose(f) == 0) && ok;
  }
  const std::string write_error = ok ? "" : std::strerror(errno);
  if (ok) fs::rename(tmp, path, ec);  // atomic: readers see the whole entry or none
  if (!ok || ec) {
    const std::string why = ok ? ec.message() : write_error;  // before the clean-up touches errno or ec
    fs::remove(tmp, ec);
    warn(fmt::format("{}: cannot write a frame cache entry ({}); the run goes on without it", path.string(), why));
    stats_.write_ms += ms_since(t0);
    return;
  }
  ++stats_.stores;
  const std::uint64_t size = sizeof h + rgb_s + depth_s;
  stats_.bytes_written += size;
  stored_since_scan_ += size;
  evict_if_full();
  stats_.write_ms += ms_since(t0);
}

// Scans the directory after every 1/16 of max_bytes written by this process: when the entries
// exceed max_bytes, the least recently used go until 90 % is left. Temporary files of writers that
// died are removed once an hour old.
void FrameCache::evict_if_full() {
  if (stored_since_scan_ < max_bytes_ / 16) return;
  stored_since_scan_ = 0;
  struct Entry {
    fs::file_time_type when;
    fs::path path;
    std::uint64_t size;
  };
  std::vector<Entry> entries;
  std::uint64_t total = 0;
  std::error_code ec;
  const auto stale = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (auto it = fs::recursive_directory_iterator(dir_, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it.depth() == 0 && it->is_directory(ec) && it->path().filename().string().size() != 2)
      it.disable_recursion_pending();  // entries live in dir/<2 hex digits>/ only
    if (it.depth() != 1 || !it->is_regular_file(ec)) continue;
    const auto when = it->last_write_time(ec);
    const auto name = it->path().filename().string();
    if (name.rfind(".tmp-", 0) == 0) {
      if (when < stale) fs::remove(it->path(), ec);
      continue;
    }
    if (it->path().extension() != ".frame") continue;
    const std::uint64_t size = it->file_size(ec);
    total += size;
    entries.push_back({when, it->path(), size});
  }
  if (total <= max_bytes_) return;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.when < b.when; });
  for (const Entry& e : entries) {
    if (total <= max_bytes_ / 10 * 9) break;
    if (fs::remove(e.path, ec)) {
      total -= e.size;
      ++stats_.evicted;
    }
  }
}

std::uint64_t parse_byte_size(std::string_view text) {
  std::uint64_t v = 0;
  std::size_t i = 0;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
    if (v > (UINT64_MAX - 9) / 10) throw std::invalid_argument(fmt::format("'{}': too large", text));
    v = v * 10 + static_cast<std::uint64_t>(text[i++] - '0');
  }
  const std::string_view unit = text.substr(i);
  int shift = -1;
  if (unit.empty() || unit == "B") shift = 0;
  else if (unit == "K" || unit == "KiB") shift = 10;
  else if (unit == "M" || unit == "MiB") shift = 20;
  else if (unit == "G" || unit == "GiB") shift = 30;
  else if (unit == "T" || unit == "TiB") shift = 40;
  if (i == 0 || shift < 0)
    throw std::invalid_argument(fmt::format("'{}': expected a size such as 20G, 512M or a number of bytes", text));
  if (shift > 0 && v > (UINT64_MAX >> shift)) throw std::invalid_argument(fmt::format("'{}': too large", text));
  return v << shift;
}

}  // namespace wingman::render
