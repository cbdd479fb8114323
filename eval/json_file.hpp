// Reading a JSON file that wingman wrote, for eval's own sources only (nlohmann-json is a private
// dependency of the library): errors name the file.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

namespace wingman::eval {

// The parsed file; std::runtime_error "<path>: cannot open" or "<path>: not valid JSON: ...".
nlohmann::json read_json_file(const std::filesystem::path& path);

}  // namespace wingman::eval
