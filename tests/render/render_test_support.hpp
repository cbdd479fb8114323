// Shared by the render tests: one GL context per backend per test process (contexts are costly
// on llvmpipe), or the reason it could not be made.
#pragma once

#include "gl_required.hpp"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <ostream>
#include <string>

#include "render/gl_context.hpp"

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
