// The frame cache (render/frame_cache.hpp): frames come back bit for bit; the key moves with
// everything that decides a frame and only with that; a damaged entry is reported, removed and
// missed; the directory stays under its bound, least recently used first; a reader never sees a
// half-written entry while another writer replaces it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "render/frame_cache.hpp"
#include "render/scene.hpp"

namespace wingman::render {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct TempDir {
  fs::path path;
  TempDir() {
    static int n = 0;
    path = fs::temp_directory_path() /
           ("wingman-frame-cache-test-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
    fs::remove_all(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

// A frame of noise (colour) and a smooth ramp with holes (depth): neither compresses to nothing.
Frame make_frame(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  Frame f;
  f.rgb.create(h, w, CV_8UC3);
  f.depth.create(h, w, CV_32FC1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      f.rgb.at<cv::Vec3b>(r, c) = {static_cast<uchar>(rng()), static_cast<uchar>(rng()), static_cast<uchar>(rng())};
      f.depth.at<float>(r, c) = (c % 17 == 0) ? 0.0f : 15.0f + 0.01f * static_cast<float>(r) + 1e-4f * static_cast<float>(rng() % 100);
    }
  return f;
}

bool same_bytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

Scene small_scene() {
  Scene s;
  Material m;
  m.texture = cv::Mat(8, 8, CV_8UC3, cv::Scalar(10, 20, 30));
  s.materials.push_back(m);
  Mesh mesh;
  mesh.add({0, 0, 0}, {0, 0, 1}, {0, 0}, {1, 1, 1});
  mesh.add({1, 0, 0}, {0, 0, 1}, {1, 0}, {1, 1, 1});
  mesh.add({0, 1, 0}, {0, 0, 1}, {0, 1}, {1, 1, 1});
  mesh.indices = {0, 1, 2};
  mesh.material = 0;
  s.static_meshes.push_back(mesh);
  return s;
}

CameraView small_view() {
  CameraView v;
  v.camera = geometry::PinholeCamera(100, 100, 50, 50, 100, 100);
  v.pose.position = {1, 2, 15};
  return v;
}

TEST(FrameCache, StoredFramesComeBackBitForBitWithEitherCodec) {
  for (FrameCodec codec : {FrameCodec::Raw, FrameCodec::Zstd}) {
    TempDir dir;
    FrameCache cache(dir.path, 1ull << 30, codec);
    const Frame f = make_frame(64, 48, 1);
    const FrameKey key{1, 2};
    EXPECT_FALSE(cache.load(key));  // nothing stored yet: a miss
    cache.store(key, f);
    const auto got = cache.load(key);
    ASSERT_TRUE(got);
    EXPECT_TRUE(same_bytes(got->rgb, f.rgb));
    EXPECT_TRUE(same_bytes(got->depth, f.depth));
    EXPECT_EQ(cache.stats().hits, 1);
    EXPECT_EQ(cache.stats().misses, 1);
    EXPECT_EQ(cache.stats().stores, 1);
    // A frame stored through a view into a larger image (not continuous) comes back whole.
    const Frame big = make_frame(80, 60, 2);
    const Frame roi{big.rgb(cv::Rect(3, 4, 64, 48)), big.depth(cv::Rect(3, 4, 64, 48))};
    cache.store({3, 4}, roi);
    const auto got_roi = cache.load({3, 4});
    ASSERT_TRUE(got_roi);
    EXPECT_TRUE(same_bytes(got_roi->rgb, roi.rgb.clone()));
    EXPECT_TRUE(same_bytes(got_roi->depth, roi.depth.clone()));
  }
}

TEST(FrameCache, ZstdEntriesAreSmallerThanRawOnes) {
  TempDir dir;
  FrameCache raw(dir.path / "raw", 1ull << 30, FrameCodec::Raw), zstd(dir.path / "zstd", 1ull << 30, FrameCodec::Zstd);
  const Frame f = make_frame(128, 128, 3);
  raw.store({1, 1}, f);
  zstd.store({1, 1}, f);
  // The depth ramp compresses; the colour noise does not: well under raw, well above nothing.
  const auto raw_size = fs::file_size(raw.entry_path({1, 1}));
  const auto zstd_size = fs::file_size(zstd.entry_path({1, 1}));
  EXPECT_LT(zstd_size, raw_size * 0.75);
  EXPECT_GT(zstd_size, 128u * 128u * 3u);
}

TEST(FrameCache, KeyMovesWithEverythingThatDecidesAFrame) {
  const Scene scene = small_scene();
  const CameraView view = small_view();
  const LeadPose lead{{3, 4, 0}, 0.5};
  const FrameKeyer keyer(scene, "EGL llvmpipe");
  const FrameKey base = keyer.key(view, lead);
  EXPECT_EQ(base, FrameKeyer(small_scene(), "EGL llvmpipe").key(small_view(), lead));  // reproducible

  std::set<std::string> keys = {base.hex()};
  auto differs = [&](const FrameKey& k, const char* what) {
    EXPECT_TRUE(keys.insert(k.hex()).second) << what << " does not change the key";
  };
  differs(FrameKeyer(scene, "OSMesa llvmpipe").key(view, lead), "the GL stack");
  Scene texel = small_scene();
  texel.materials[0].texture.at<cv::Vec3b>(7, 7)[2] ^= 1;
  differs(FrameKeyer(texel, "EGL llvmpipe").key(view, lead), "one texel");
  Scene vertex = small_scene();
  vertex.static_meshes[0].positions[4] = std::nextafter(vertex.static_meshes[0].positions[4], 1.0f);
  differs(FrameKeyer(vertex, "EGL llvmpipe").key(view, lead), "one vertex");
  Scene msaa = small_scene();
  msaa.msaa = 1;
  differs(FrameKeyer(msaa, "EGL llvmpipe").key(view, lead), "MSAA");
  CameraView moved = view;
  moved.pose.position.x() = std::nextafter(1.0, 2.0);
  differs(keyer.key(moved, lead), "the camera's position by one ulp");
  CameraView turned = view;
  turned.pose.R_CW(0, 1) = 1e-12;
  differs(keyer.key(turned, lead), "the camera's rotation");
  CameraView intrinsics = view;
  intrinsics.camera = geometry::PinholeCamera(100, 100.5, 50, 50, 100, 100);
  differs(keyer.key(intrinsics, lead), "fy");
  CameraView distorted = view;
  distorted.camera = geometry::PinholeCamera(100, 100, 50, 50, 100, 100, {0, 0, 0, 0, 1e-6});
  differs(keyer.key(distorted, lead), "k3");
  differs(keyer.key(view, LeadPose{{3, 4, 0}, 0.5000001}), "the lead's heading");
  differs(keyer.key(view, std::nullopt), "no lead");
}

TEST(FrameCache, DamagedEntriesAreReportedRemovedAndMissed) {
  TempDir dir;
  FrameCache cache(dir.path, 1ull << 30);
  std::vector<std::string> warnings;
  cache.on_warning([&](const std::string& w) { warnings.push_back(w); });
  const Frame f = make_frame(64, 48, 4);
  struct Damage {
    const char* name;
    std::function<void(const fs::path&)> apply;
    const char* why;
  };
  const std::vector<Damage> damages = {
      {"a flipped payload byte", [](const fs::path& p) {
         std::fstream io(p, std::ios::in | std::ios::out | std::ios::binary);
         io.seekp(200);
         io.put('\x5a');
       }, "checksum mismatch"},
      {"a truncated file", [](const fs::path& p) { fs::resize_file(p, fs::file_size(p) - 10); }, "wrong size"},
      {"a header byte", [](const fs::path& p) {
         std::fstream io(p, std::ios::in | std::ios::out | std::ios::binary);
         io.seekp(30);
         io.put('\x01');
       }, "bad header"},
      {"an empty file", [](const fs::path& p) { std::ofstream(p, std::ios::trunc); }, "shorter than its header"}};
  for (const Damage& d : damages) {
    cache.store({9, 9}, f);
    const fs::path p = cache.entry_path({9, 9});
    d.apply(p);
    warnings.clear();
    EXPECT_FALSE(cache.load({9, 9})) << d.name;
    ASSERT_EQ(warnings.size(), 1u) << d.name;
    EXPECT_THAT(warnings[0], HasSubstr(p.string())) << d.name;
    EXPECT_THAT(warnings[0], HasSubstr(d.why)) << d.name;
    EXPECT_FALSE(fs::exists(p)) << d.name;
    cache.store({9, 9}, f);  // rendered again and stored: whole once more
    EXPECT_TRUE(cache.load({9, 9})) << d.name;
  }
  EXPECT_EQ(cache.stats().corrupt, static_cast<long>(damages.size()));
}

TEST(FrameCache, StaysUnderItsBoundDroppingTheLeastRecentlyUsed) {
  TempDir dir;
  const Frame f = make_frame(64, 64, 5);
  FrameCache probe(dir.path / "probe", 1ull << 30, FrameCodec::Raw);
  probe.store({0, 0}, f);
  const std::uint64_t entry = fs::file_size(probe.entry_path({0, 0}));
  // Room for four entries; every store past 1/16 of the bound rescans.
  FrameCache cache(dir.path / "cache", 4 * entry + entry / 2, FrameCodec::Raw);
  const auto base = fs::file_time_type::clock::now() - std::chrono::hours(2);
  for (std::uint64_t i = 0; i < 4; ++i) {
    cache.store({i, i}, f);
    fs::last_write_time(cache.entry_path({i, i}), base + std::chrono::minutes(i));
  }
  ASSERT_TRUE(cache.load({0, 0}));  // the oldest, now the most recently used
  cache.store({4, 4}, f);           // the fifth: over the bound
  std::uint64_t total = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir.path / "cache"))
    if (e.is_regular_file()) total += e.file_size();
  EXPECT_LE(total, 4 * entry + entry / 2);
  EXPECT_TRUE(fs::exists(cache.entry_path({0, 0})));   // used recently: kept
  EXPECT_FALSE(fs::exists(cache.entry_path({1, 1})));  // least recently used: gone
  EXPECT_TRUE(fs::exists(cache.entry_path({4, 4})));
  EXPECT_GE(cache.stats().evicted, 1);
}

TEST(FrameCache, ReadersNeverSeeAHalfWrittenEntry) {
  TempDir dir;
  const Frame a = make_frame(200, 150, 6);
  std::atomic<bool> stop{false};
  std::atomic<int> stored{0};
  std::thread writer([&] {
    FrameCache w(dir.path, 1ull << 30);  // another process's cache in the same directory
    while (!stop) {
      w.store({7, 7}, a);
      ++stored;
    }
  });
  while (stored == 0) std::this_thread::yield();
  FrameCache r(dir.path, 1ull << 30);
  std::vector<std::string> warnings;
  r.on_warning([&](const std::string& w) { warnings.push_back(w); });
  int hits = 0;
  for (int i = 0; i < 200 || stored < 20; ++i) {  // the entry replaced many times meanwhile
    if (auto got = r.load({7, 7})) {
      ++hits;
      ASSERT_TRUE(same_bytes(got->rgb, a.rgb) && same_bytes(got->depth, a.depth));
    }
  }
  stop = true;
  writer.join();
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_GE(hits, 200);  // every read found a whole entry
}

TEST(FrameCache, NeverTakesOverADirectoryOfOtherFiles) {
  TempDir dir;
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "thesis.tex") << "mine";
  EXPECT_THROW(FrameCache(dir.path, 1ull << 30), std::runtime_error);
  EXPECT_TRUE(fs::exists(dir.path / "thesis.tex"));
  // An empty directory becomes one, and opens again as one once it holds entries.
  TempDir empty;
  fs::create_directories(empty.path);
  FrameCache(empty.path, 1ull << 30).store({1, 1}, make_frame(16, 16, 7));
  FrameCache again(empty.path, 1ull << 30);
  EXPECT_TRUE(again.load({1, 1}));
}

TEST(FrameCache, SizesReadAsBytesWithBinaryUnits) {
  EXPECT_EQ(parse_byte_size("1048576"), 1048576u);
  EXPECT_EQ(parse_byte_size("512M"), 512ull << 20);
  EXPECT_EQ(parse_byte_size("40G"), 40ull << 30);
  EXPECT_EQ(parse_byte_size("2GiB"), 2ull << 30);
  for (const char* bad : {"", "G", "12X", "-1G", "1.5G", "99999999999999999999"})
    EXPECT_THROW(parse_byte_size(bad), std::invalid_argument) << bad;
}

}  // namespace
}  // namespace wingman::render
