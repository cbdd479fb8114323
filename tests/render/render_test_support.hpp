// Shared by the render tests: one GL context per backend per test process (contexts are costly
// on llvmpipe), or the reason it could not be made; a scene of bright targets on dark ground and
// the centroid that finds them.
#pragma once

#include "gl_required.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "render/gl_context.hpp"
#include "render/scene.hpp"

namespace wingman::render::testing {

struct ContextOrWhy {
  std::unique_ptr<GlContext> ctx;
  std::string why;
};

inline ContextOrWhy& context_for(GlBackend b) {
  static std::map<GlBackend, ContextOrWhy> cache;
  auto it = cache.find(b);
  if (it != cache.end()) return it->second;
  ContextOrWhy c;
  try {
    c.ctx = create_gl_context(b);
  } catch (const GlContextError& e) {
    c.why = e.what();
  }
  return cache.emplace(b, std::move(c)).first->second;
}

// A horizontal square of side s at p, turned by yaw about z, unlit, in colour c.
inline Mesh square(const Eigen::Vector3d& p, double s, const Eigen::Vector3d& c, int material, double yaw = 0) {
  Mesh m;
  m.material = material;
  const double h = s / 2, cs = std::cos(yaw), sn = std::sin(yaw);
  const double corners[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  const double uvs[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 4; ++i) {
    const double x = corners[i][0], y = corners[i][1];
    m.add(p + Eigen::Vector3d(cs * x - sn * y, sn * x + cs * y, 0), {0, 0, 1}, {uvs[i][0], uvs[i][1]}, c);
  }
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Bright targets (turned by yaw: slanted edges average the rasteriser's coverage steps out).
inline Scene target_scene(const std::vector<Eigen::Vector3d>& targets, double side, double yaw = 0) {
  Scene s;
  Material unlit;
  unlit.unlit = true;
  s.materials.push_back(unlit);
  s.static_meshes.push_back(square({0, 0, 0}, 400, {0, 0, 0}, 0));  // dark ground
  for (const auto& t : targets) s.static_meshes.push_back(square(t, side, {1, 1, 1}, 0, yaw));
  s.sky = {0, 0, 0};
  s.msaa = 4;
  return s;
}

// Intensity-weighted centroid of the bright blob around a pixel.
inline Eigen::Vector2d centroid(const cv::Mat& gray, const Eigen::Vector2d& near, int radius) {
  double sw = 0, su = 0, sv = 0;
  for (int r = std::max(0, int(near.y()) - radius); r <= std::min(gray.rows - 1, int(near.y()) + radius); ++r)
    for (int c = std::max(0, int(near.x()) - radius); c <= std::min(gray.cols - 1, int(near.x()) + radius); ++c) {
      const double w = gray.at<uchar>(r, c);
      sw += w, su += w * c, sv += w * r;
    }
  return {su / sw, sv / sw};
}

inline std::string backend_name(const ::testing::TestParamInfo<GlBackend>& info) {
  return to_string(info.param);
}

}  // namespace wingman::render::testing

// Skips (printing why) only when this backend truly cannot make a context; fails under CI=true.
#define WINGMAN_REQUIRE_CONTEXT(backend, var)                                         \
  auto& var##_entry = ::wingman::render::testing::context_for(backend);                \
  if (!var##_entry.ctx)                                                                \
    WINGMAN_NO_GL_CONTEXT(std::string("no ") + to_string(backend) + " context: " + var##_entry.why); \
  ::wingman::render::GlContext& var = *var##_entry.ctx

namespace wingman::render {
// How gtest prints a backend parameter (by name, not as a number).
inline void PrintTo(GlBackend b, std::ostream* os) { *os << to_string(b); }
}  // namespace wingman::render
