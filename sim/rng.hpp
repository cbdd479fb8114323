// Reproducible random streams: each consumer (landmark field, pixel noise, outliers, GPS, ...)
// draws from its own generator derived from the scenario seed, so adding draws to one stream
// never changes another.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string_view>

namespace wingman::sim {

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline std::mt19937_64 make_stream(std::uint64_t seed, std::string_view name) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the stream name
  for (char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return std::mt19937_64(splitmix64(seed ^ splitmix64(h)));
}

// Three independent N(0, sigma^2) draws, x then y then z, so that a seed means one vector.
// `unit` is N(0, 1) and kept by the caller across draws: it caches every second value.
inline Eigen::Vector3d gaussian3(std::mt19937_64& rng, std::normal_distribution<double>& unit,
                                 double sigma) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v(i) = sigma * unit(rng);
  return v;
}

}  // namespace wingman::sim
