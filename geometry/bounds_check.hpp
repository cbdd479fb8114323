// The bounds a settings struct's visit() declares, checked on values set in code: the one home of
// every limit (geometry/settings.hpp). The scenario reader checks the same bounds on what it
// reads, with the file, line and key; this checker serves a struct filled by a program, throwing
// std::invalid_argument that names the key path and its bounds.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "geometry/settings.hpp"

namespace wingman::geometry {

// ">= 1", "in (0, 1]", "< 5".
std::string bounds_text(const Bounds& b);

class BoundsChecker {
 public:
  BoundsChecker(std::string_view what, std::string prefix) : what_(what), prefix_(std::move(prefix)) {}

  void operator()(std::string_view key, double& x, Bounds b = {}) { check(key, x, b); }
  void operator()(std::string_view key, float& x, Bounds b = {}) { check(key, x, b); }
  void operator()(std::string_view key, int& x, Bounds b = {}) { check(key, x, b); }
  // An `auto` value not yet derived holds only its fallback, which is not the user's.
  void operator()(std::string_view key, AutoNumber& x, Bounds b = {}) {
    if (!x.automatic || !x.source.empty()) check(key, x.value, b);
  }
  template <int N>
  void operator()(std::string_view key, Eigen::Matrix<double, N, 1>& x, Bounds b = {}) {
    for (int i = 0; i < N; ++i) check(key, x[i], b);
  }
  template <typename T, typename... Rest>
  void operator()(std::string_view, T&, Rest&&...) {}  // a flag, a name, a path: no bounds
  template <typename E>
  void choice(std::string_view, E&, Choices<E>) {}
  template <typename Fn>
  void section(std::string_view key, Fn&& fn) {
    BoundsChecker sub(what_, path(key) + ".");
    fn(sub);
  }
  void pair(std::string_view key, int& a, int& b, Bounds bounds = {}) {
    check(key, a, bounds);
    check(key, b, bounds);
  }
  template <typename T>
  void list(std::string_view key, std::vector<T>& items, ListNames) {
    for (std::size_t i = 0; i < items.size(); ++i) {
      BoundsChecker sub(what_, path(key) + "[" + std::to_string(i) + "].");
      items[i].visit(sub);
    }
  }
  // What the scenario reader alone checks: conditions on the file's values, required keys.
  void check(std::string_view, bool, std::string_view) {}
  void required(std::string_view) {}
  template <typename T>
  void optional(std::string_view, T&) {}
  void other(std::string_view) {}

 private:
  std::string path(std::string_view key) const { return prefix_ + std::string(key); }
  void check(std::string_view key, double v, const Bounds& b) const;
  std::string_view what_;
  std::string prefix_;
};

// Checks every bounded key of `settings` (a struct with visit()); `what` names the struct in the
// message: "feature settings: orb.levels must be in [1, 16], got 20".
template <typename S>
void check_bounds(const S& settings, std::string_view what) {
  S copy = settings;  // visit() takes its fields by reference
  BoundsChecker checker(what, "");
  copy.visit(checker);
}

}  // namespace wingman::geometry
