// One definition per setting. A module's settings struct names each of its keys once, in a
// `visit` member template:
//
//   template <class V> void visit(V& v) {
//     v("pixel_sigma", pixel_sigma, ge(0));
//     v.section("gating", [&](auto& g) { g("probability", gate_probability, in(0, 1, true, true)); });
//   }
//
// and every walker of settings is such a V: the scenario reader (sim/settings_yaml.hpp) fills the
// struct from YAML with file:line:key errors, the printer writes the resolved values, the
// documentation test compares docs/scenario.md with the defaults. A visitor takes
//   v(key, double&, Bounds)   v(key, int&, Bounds)   v(key, bool&)   v(key, std::string&)
//   v(key, Eigen::Vector3d&)  v(key, Eigen::Vector4d&, Bounds)  v(key, SeedSetting&)
//   v(key, AutoNumber&, Bounds)  (a number or `auto`)
//   v.choice(key, E&, {{"name", E::Value}, ...})
//   v.section(key, [&](auto& sub) { ... })
//   v.list(key, std::vector<T>&, ListNames)   (a list of maps, each T with its own visit())
//   v.optional(key, std::string&)              (written only when set)
//   v.required(key)                            (the reader fails when the key is absent)
//   v.check(key, ok, what)                     (a condition on the values read so far)
// Keys are YAML keys; the struct's field names may differ (the code's names stay frame- and
// unit-explicit).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>
#include <utility>

namespace wingman::geometry {

// The admissible range of a number: [lo, hi] with either end open.
struct Bounds {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  bool ok(double v) const {
    if (lo_open ? !(v > lo) : !(v >= lo)) return false;
    if (hi_open ? !(v < hi) : !(v <= hi)) return false;
    return true;
  }
};

inline Bounds any_value() { return {}; }
inline Bounds ge(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
inline Bounds gt(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, false}; }
inline Bounds in(double lo, double hi, bool lo_open = false, bool hi_open = false) {
  return {lo, hi, lo_open, hi_open};
}

// A seed that is a fixed number or, written `per_run`, the run's own seed.
struct SeedSetting {
  bool per_run = false;
  std::uint64_t value = 1;
  // The seed to draw from in a run of seed `run_seed`.
  std::uint64_t resolve(std::uint64_t run_seed) const { return per_run ? run_seed : value; }
  bool operator==(const SeedSetting&) const = default;
};

// A number a scenario may leave to the run (`auto`, the default of such keys): the run derives it
// from what the scenario flies or from the frontend's noise model, and the resolved configuration
// prints the value with where it came from. A number written in the file is taken as it is.
struct AutoNumber {
  double value = 0;
  bool automatic = true;
  std::string source;  // where a derived value came from; empty while unresolved

  AutoNumber() = default;
  // `fallback` is what code that never resolves the setting (a test's settings struct) uses.
  explicit AutoNumber(double fallback) : value(fallback) {}
  // A value set in code is the user's: never derived over.
  AutoNumber& operator=(double v) {
    value = v;
    automatic = false;
    source.clear();
    return *this;
  }
  operator double() const { return value; }  // NOLINT: reads as the number it holds
  // Sets a derived value (only while automatic: a value the user wrote stays).
  void derive(double v, std::string why) {
    if (!automatic) return;
    value = v;
    source = std::move(why);
  }
};

// How a list of maps is named in messages, and how many items it needs at least.
struct ListNames {
  std::string_view plural, singular;
  std::size_t min_items = 0;
};

// The names an enum takes in files, in the order they are listed to a user.
template <typename E>
using Choices = std::initializer_list<std::pair<std::string_view, E>>;

}  // namespace wingman::geometry
