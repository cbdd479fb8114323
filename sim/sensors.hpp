// The measurement kinds and the configurations of Table 1 that switch them on or off.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace wingman::sim {

// Measurement kinds a configuration switches on or off (Table 1).
enum class Sensor { Landmarks, LeadProjection, Altimeter, Range, Gps };
const char* to_string(Sensor s);
std::optional<Sensor> sensor_from_string(const std::string& s);

// Table 1 presets; Integrated feeds everything available at that instant.
enum class Config { C1, C2, C3, Integrated };
const char* to_string(Config c);
// The sensor set of a configuration preset.
std::vector<Sensor> sensors_of(Config c);

}  // namespace wingman::sim
