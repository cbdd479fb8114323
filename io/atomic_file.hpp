// Writing a file so that it is either complete or absent: the content goes to a temporary
// sibling, is flushed to the disk, and is renamed over the target. Every step is checked, so a
// full disk is an error naming the file, never a 0-byte montecarlo.json that looks written.
#pragma once

#include <filesystem>
#include <string_view>

namespace wingman::io {

// Throws std::runtime_error naming `path` and the system's reason; the target is untouched then.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

}  // namespace wingman::io
