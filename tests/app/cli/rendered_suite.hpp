// A test suite that renders its datasets once, in SetUpTestSuite: skipped (or, under CI, failed)
// where no GL context can be made, and failing every test when the render failed. `Suite`
// derives from RenderedSuite<Suite> (each suite its own statics) and defines
// `static std::string render(const fs::path& dir)`: the render's output when it failed, else "".
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "app/app_test_support.hpp"
#include "gl_required.hpp"

namespace wingman::app::test {

template <class Suite>
class RenderedSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string why;
    if (!wingman::testing::gl_available(&why)) {
      skip_reason_ = why;
      return;
    }
    dir_ = new TempDir();
    render_error_ = Suite::render(dir_->path());
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!skip_reason_.empty()) WINGMAN_NO_GL_CONTEXT(skip_reason_);
    ASSERT_TRUE(render_error_.empty()) << render_error_;
  }
  static fs::path tmp() { return dir_->path(); }

  static inline TempDir* dir_ = nullptr;
  static inline std::string skip_reason_, render_error_;
};

}  // namespace wingman::app::test
