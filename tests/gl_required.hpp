// Tests that need an OpenGL context: where the machine cannot make one they are skipped, saying
// why; under CI=true they fail instead, so that a CI run cannot pass without rendering anything.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "render/gl_context.hpp"

namespace wingman::testing {

// Whether this machine can make an OpenGL context of any backend; if not, *why says why.
inline bool gl_available(std::string* why) {
  try {
    render::create_gl_context(render::GlBackend::Auto);
    return true;
  } catch (const render::GlContextError& e) {
    *why = e.what();
    return false;
  }
}

inline bool gl_required() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace wingman::testing

// Ends the test for want of a context: a failure under CI=true, a skip otherwise.
#define WINGMAN_NO_GL_CONTEXT(why)                                                   \
  do {                                                                               \
    if (::wingman::testing::gl_required()) FAIL() << "CI=true and no OpenGL context: " << (why); \
    GTEST_SKIP() << (why);                                                           \
  } while (0)
