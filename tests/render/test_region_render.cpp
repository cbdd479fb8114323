// Region rendering: only the pixels inside a frame's regions are drawn and read back, under a
// scissor rectangle with the whole frame's projection, so they are the whole frame's pixels there
// (the chunks of the scene outside a region skipped, a box's pixels outside its regions masked).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "geometry/rotation.hpp"
#include "render/renderer.hpp"
#include "render_test_support.hpp"

namespace wingman::render {
namespace {

using testing::backend_name;

// A 60 m ground of 1 m cells with relief, so that the renderer splits it into chunks, some
// outside each region.
Mesh rough_ground(int material) {
  Mesh m;
  m.material = material;
  constexpr int n = 60;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = j - n / 2.0, y = i - n / 2.0;
      m.add({x, y, 0.4 * std::sin(0.7 * x) * std::cos(0.5 * y) - 0.5}, {0, 0, 1}, {j / 8.0, i / 8.0}, {1, 1, 1});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto a = static_cast<std::uint32_t>(i * (n + 1) + j), b = a + 1, c = a + n + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
    }
  return m;
}

// A textured ground (mipmapped noise, sampled trilinearly) with bright targets on it.
Scene textured_scene(int msaa) {
  Scene s = testing::target_scene({{0, 0, 0.01}, {3, 2, 0.01}, {-4, -3, 0.01}}, 0.6, 0.3);
  Material ground;
  ground.texture = cv::Mat(256, 256, CV_8UC3);
  cv::randu(ground.texture, cv::Scalar::all(0), cv::Scalar::all(255));
  s.materials.push_back(ground);
  s.static_meshes.front() = rough_ground(1);
  s.msaa = msaa;
  return s;
}

class RegionRenderTest : public ::testing::TestWithParam<GlBackend> {};

// Four regions inside, on the border, and partly outside the image (clipped to it); 40 small
// squares scattered over it, which the renderer draws in fewer boxes whose other pixels the depth
// buffer masks; thin bars that cross, each its own draw over part of another's region; and a bar
// drawn first, then two squares drawn as one box that crosses it.
std::vector<std::vector<cv::Rect>> region_sets() {
  std::vector<cv::Rect> scattered;
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> x(-10, 310), y(-10, 230), side(6, 30);
  for (int i = 0; i < 40; ++i) scattered.emplace_back(x(rng), y(rng), side(rng), side(rng));
  return {{{40, 30, 64, 48}, {150, 100, 33, 57}, {0, 200, 90, 40}, {290, -10, 60, 50}},
          scattered,
          {{10, 20, 250, 8}, {30, 5, 8, 220}, {200, 100, 110, 6}, {220, 60, 6, 150}},
          {{0, 130, 320, 3}, {100, 100, 20, 20}, {140, 140, 20, 20}}};
}

TEST_P(RegionRenderTest, ARegionsPixelsAreTheWholeFramesAndTheRestIsZero) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const geometry::PinholeCamera cam(210.3, 190.7, 161.3, 118.6, 320, 240);
  const CameraView view{cam, {geometry::nadir_R_CW(), {0.37, -0.21, 20}}};
  for (const int msaa : {1, 4}) {
    Renderer r(ctx, textured_scene(msaa));
    const Frame whole = r.render(view);
    EXPECT_GT(cv::norm(whole.rgb, cv::NORM_INF), 100);  // the texture is there
    for (const auto& regions : region_sets()) {
      SCOPED_TRACE("msaa " + std::to_string(msaa) + ", " + std::to_string(regions.size()) + " regions");
      const Frame part = r.render_regions(view, std::nullopt, regions);
      ASSERT_EQ(part.rgb.size(), whole.rgb.size());
      cv::Mat inside = cv::Mat::zeros(whole.rgb.size(), CV_8U);
      for (const cv::Rect& reg : regions) {
        const cv::Rect c = reg & cv::Rect(0, 0, cam.width(), cam.height());
        inside(c).setTo(255);
        EXPECT_EQ(cv::norm(part.rgb(c), whole.rgb(c), cv::NORM_INF), 0) << "region " << reg << " on " << ctx.description();
        EXPECT_EQ(cv::norm(part.depth(c), whole.depth(c), cv::NORM_INF), 0) << "region " << reg;
      }
      cv::Mat outside;
      cv::bitwise_not(inside, outside);
      EXPECT_EQ(cv::norm(part.rgb, cv::NORM_INF, outside), 0);
      EXPECT_EQ(cv::norm(part.depth, cv::NORM_INF, outside), 0);
    }
    EXPECT_EQ(cv::countNonZero(r.render_regions(view, std::nullopt, {}).depth), 0);  // no region: nothing
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, RegionRenderTest, ::testing::Values(GlBackend::Egl, GlBackend::OsMesa),
                         backend_name);

}  // namespace
}  // namespace wingman::render
