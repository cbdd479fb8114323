// Stochastic tiling of a ground texture, with both backends: a nadir frame over several copies of
// the image shows no copy again one period away (where repeat tiling shows the very same pixels),
// keeps the image's mean and contrast, and never wraps a piece over the image's border (where
// repeat tiling draws the seam of a photo that is not periodic), and shows at each grid vertex the
// piece its table places there.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

#include "geometry/rotation.hpp"
#include "render/ground_bake.hpp"
#include "render/piece_table.hpp"
#include "render/renderer.hpp"
#include "render_test_support.hpp"

namespace wingman::render {
namespace {

using testing::backend_name;

constexpr double kTileW = 20, kTileH = 15;  // m one copy of the 256 x 192 image covers

// A flat 200 m square whose texture coordinates repeat every kTileW x kTileH metres.
Mesh tiled_ground() {
  Mesh m;
  m.material = 0;
  const double h = 100;
  for (const auto& [x, y] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, h}})
    m.add({x, y, 0}, {0, 0, 1}, {x / kTileW, -y / kTileH}, {1, 1, 1});
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Smooth random texture (features some 8 texels across), grey levels about 128 +- 40.
cv::Mat noise_texture() {
  cv::Mat n(192, 256, CV_32F);
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0, 1);
  for (int r = 0; r < n.rows; ++r)
    for (int c = 0; c < n.cols; ++c) n.at<float>(r, c) = g(rng);
  cv::GaussianBlur(n, n, cv::Size(0, 0), 3, 3, cv::BORDER_REFLECT);
  cv::Scalar mean, sd;
  cv::meanStdDev(n, mean, sd);
  cv::Mat u8;
  n.convertTo(u8, CV_8U, 40 / sd[0], 128 - 40 * mean[0] / sd[0]);
  cv::Mat rgb;
  cv::cvtColor(u8, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}

// A ramp from black at the image's left edge to white at its right: a seam wherever it wraps.
cv::Mat ramp_texture() {
  cv::Mat g(192, 256, CV_8U);
  for (int c = 0; c < g.cols; ++c) g.col(c).setTo(c);
  cv::Mat rgb;
  cv::cvtColor(g, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}

Scene ground_scene(const cv::Mat& texture, bool stochastic) {
  Scene s;
  Material m;
  m.texture = texture;
  m.unlit = true;  // the frame shows the texture's own grey levels
  if (stochastic) m.stochastic_cell = 0.25;
  s.materials.push_back(m);
  s.static_meshes.push_back(tiled_ground());
  s.msaa = 1;
  return s;
}

// 10 cm a pixel from 40 m: the 400 x 400 frame spans 2 x 2.7 copies; one period is 200 px across.
cv::Mat nadir_frame(GlContext& ctx, const cv::Mat& texture, bool stochastic) {
  const geometry::PinholeCamera cam(400, 400, 199.5, 199.5, 400, 400);
  Renderer r(ctx, ground_scene(texture, stochastic));
  cv::Mat g;
  cv::cvtColor(r.render({cam, {geometry::nadir_R_CW(), {3, -2, 40}}}).rgb, g, cv::COLOR_RGB2GRAY);
  return g;
}

double ncc(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat r;
  cv::matchTemplate(a, b, r, cv::TM_CCOEFF_NORMED);
  return r.at<float>(0, 0);
}

class StochasticTilingTest : public ::testing::TestWithParam<GlBackend> {};

TEST_P(StochasticTilingTest, NoCopyOfTheImageRecursOnePeriodAway) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const cv::Mat tex = noise_texture();
  const cv::Mat repeat = nadir_frame(ctx, tex, false), stochastic = nadir_frame(ctx, tex, true);
  double worst = -1;
  for (const auto& [c, r] : {std::pair{20, 20}, {60, 150}, {100, 300}, {130, 60}}) {
    const cv::Rect a(c, r, 64, 64), b(c + 200, r, 64, 64);  // one period (20 m) to the east
    EXPECT_GT(ncc(repeat(a), repeat(b)), 0.97) << c << ", " << r;
    worst = std::max(worst, ncc(stochastic(a), stochastic(b)));
  }
  EXPECT_LT(worst, 0.5);
}

// A texture whose red and green levels are its own column and row (scaled to 0-255): each pixel of
// a frame says which texel of the image it shows.
cv::Mat coordinate_texture() {
  cv::Mat rgb(192, 256, CV_8UC3);
  for (int r = 0; r < rgb.rows; ++r)
    for (int c = 0; c < rgb.cols; ++c)
      rgb.at<cv::Vec3b>(r, c) = {static_cast<std::uint8_t>(c), static_cast<std::uint8_t>(std::lround(r * 255.0 / 191)), 128};
  return rgb;
}

// Where the pieces lie is the piece table's (render/piece_table.hpp, whose tests check that nearby
// vertices never show copies of the same ground a short way apart): at every grid vertex in view,
// where that vertex's piece has all the weight, the frame shows the image at the table's centre.
TEST_P(StochasticTilingTest, EachGridVertexShowsTheImageAtItsTablesCentre) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const geometry::PinholeCamera cam(400, 400, 199.5, 199.5, 400, 400);
  const Eigen::Vector3d C(3, -2, 40);
  Renderer r(ctx, ground_scene(coordinate_texture(), true));
  const cv::Mat frame = r.render({cam, {geometry::nadir_R_CW(), C}}).rgb;
  const double aspect = 0.75, cell = 0.25 * aspect;  // in units of the image's width (20 m)
  const PieceTable table = piece_table(cell, aspect, 0);
  int checked = 0;
  double worst = 0;
  for (int j = -20; j <= 20; ++j)
    for (int i = -20; i <= 20; ++i) {
      // The vertex in texture space (u across, v * aspect down), then on the ground: u = x / 20,
      // v = -y / 15.
      const double qx = cell * (i + 0.5 * j), qy = cell * 0.8660254037844386 * j;
      const Eigen::Vector3d p(kTileW * qx, -kTileH * qy / aspect, 0);
      const auto px = cam.project(geometry::nadir_R_CW() * (p - C));
      if (!px || px->x() < 2 || px->y() < 2 || px->x() > 397 || px->y() > 397) continue;
      const cv::Vec3b got = frame.at<cv::Vec3b>(static_cast<int>(std::lround(px->y())), static_cast<int>(std::lround(px->x())));
      double u, v;
      table.centre(i, j, u, v);
      // The piece lies where the table says, its shift rounded to whole blocks of
      // kBakeBlockTexels texels (kStochasticLookup); texel centres carry their index: u =
      // (level + 0.5) / 256 across, v / aspect likewise down.
      const double k = kBakeBlockTexels, at_u = qx * 256, at_v = qy / aspect * 192;
      const double shown_u = at_u + k * std::round((u * 256 - at_u) / k);
      const double shown_v = at_v + k * std::round((v / aspect * 192 - at_v) / k);
      const double want_r = shown_u - 0.5, want_g = (shown_v - 0.5) * 255 / 191;
      worst = std::max({worst, std::abs(got[0] - want_r), std::abs(got[1] - want_g)});
      ++checked;
    }
  EXPECT_GT(checked, 100);
  // Half a pixel from the vertex moves the reading by 0.7 levels; filtering and rounding add one.
  EXPECT_LT(worst, 2.0) << checked << " vertices";
}

TEST_P(StochasticTilingTest, TheImagesMeanAndContrastAreKept) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const cv::Mat tex = noise_texture();
  cv::Scalar m_rep, sd_rep, m_st, sd_st;
  cv::meanStdDev(nadir_frame(ctx, tex, false), m_rep, sd_rep);
  cv::meanStdDev(nadir_frame(ctx, tex, true), m_st, sd_st);
  // The frame holds some 40 pieces drawn from the image's interior: their mean strays from the
  // image's by a few grey levels, a tenth of its spread.
  EXPECT_NEAR(m_st[0], m_rep[0], 0.2 * sd_rep[0]);
  EXPECT_NEAR(sd_st[0] / sd_rep[0], 1.0, 0.1) << sd_st[0] << " against " << sd_rep[0];
}

TEST_P(StochasticTilingTest, NoPieceWrapsOverTheImagesBorder) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const cv::Mat tex = ramp_texture();
  auto steepest = [](const cv::Mat& g) {  // the largest step between neighbours along a row
    cv::Mat d;
    cv::absdiff(g.colRange(1, g.cols), g.colRange(0, g.cols - 1), d);
    double hi = 0;
    cv::minMaxLoc(d, nullptr, &hi);
    return hi;
  };
  EXPECT_GT(steepest(nadir_frame(ctx, tex, false)), 150);  // the seam, once a period
  EXPECT_LT(steepest(nadir_frame(ctx, tex, true)), 80);
}

INSTANTIATE_TEST_SUITE_P(Backends, StochasticTilingTest,
                         ::testing::Values(GlBackend::Egl, GlBackend::OsMesa), backend_name);

}  // namespace
}  // namespace wingman::render
