// Tests that need an OpenGL context: where the machine cannot make one they are skipped, saying
// why; under CI=true they fail instead, so that a CI run cannot pass without rendering anything.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace wingman::testing {

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
