// The bounds a visit() declares, checked on values set in code.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "geometry/bounds_check.hpp"

namespace wingman::geometry {
namespace {

struct Example {
  int levels = 4;
  double ratio = 0.8;
  int cols = 8, rows = 8;
  AutoNumber sigma;
  bool flag = false;
  std::string name = "x";
  template <class V>
  void visit(V& v) {
    v("ratio", ratio, in(0, 1, true, false));
    v("flag", flag);
    v("name", name);
    v("sigma", sigma, gt(0));
    v.pair("grid", cols, rows, ge(1));
    v.section("orb", [&](auto& o) { o("levels", levels, in(1, 16)); });
  }
};

std::string message_of(const Example& e) {
  try {
    check_bounds(e, "example settings");
  } catch (const std::invalid_argument& x) {
    return x.what();
  }
  return "";
}

TEST(BoundsCheck, DefaultsInsideTheirBoundsPass) { EXPECT_EQ(message_of(Example{}), ""); }

TEST(BoundsCheck, AValueOutsideANestedBoundNamesItsKeyPathAndTheBound) {
  Example e;
  e.levels = 20;
  EXPECT_EQ(message_of(e), "example settings: orb.levels must be in [1, 16], got 20");
}

TEST(BoundsCheck, OpenEndsPairsAndSetNumbersAreChecked) {
  Example e;
  e.ratio = 0;
  EXPECT_EQ(message_of(e), "example settings: ratio must be in (0, 1], got 0");
  e = {};
  e.rows = 0;
  EXPECT_EQ(message_of(e), "example settings: grid must be >= 1, got 0");
  e = {};
  e.sigma = -1.0;
  EXPECT_EQ(message_of(e), "example settings: sigma must be > 0, got -1");
}

TEST(BoundsCheck, AnAutoNumberNotYetDerivedIsNotChecked) {
  Example e;  // sigma automatic with fallback 0, outside gt(0)
  EXPECT_EQ(message_of(e), "");
  e.sigma.derive(-2, "derived");
  EXPECT_NE(message_of(e).find("sigma must be > 0, got -2"), std::string::npos);
}

}  // namespace
}  // namespace wingman::geometry
