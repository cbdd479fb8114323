// Reproducible random streams: each consumer (landmark field, pixel noise, outliers, GPS, ...)
// draws from its own generator derived from the scenario seed, so adding draws to one stream
// never changes another.
#pragma once

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

}  // namespace wingman::sim
