#include "geometry/bounds_check.hpp"

#include <fmt/core.h>

#include <limits>
#include <stdexcept>

namespace wingman::geometry {

std::string bounds_text(const Bounds& b) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (b.hi == kInf) return fmt::format("{} {}", b.lo_open ? ">" : ">=", b.lo);
  if (b.lo == -kInf) return fmt::format("{} {}", b.hi_open ? "<" : "<=", b.hi);
  return fmt::format("in {}{}, {}{}", b.lo_open ? '(' : '[', b.lo, b.hi, b.hi_open ? ')' : ']');
}

void BoundsChecker::check(std::string_view key, double v, const Bounds& b) const {
  if (!b.ok(v))
    throw std::invalid_argument(fmt::format("{}: {} must be {}, got {}", what_, path(key), bounds_text(b), v));
}

}  // namespace wingman::geometry
