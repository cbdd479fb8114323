#include "app/batch/montecarlo_study.hpp"

#include <fmt/core.h>

#include <cstdint>
#include <fstream>
#include <sstream>

#include "io/usage_error.hpp"
#include "io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::size_t indent(const std::string& l) { return l.find_first_not_of(' '); }

// The dotted key path of line i of a block-style YAML text: the keys of the lines above it with
// less indentation, as config_yaml writes them.
std::string key_path(const std::vector<std::string>& lines, std::size_t i) {
  std::string path = lines[i].substr(indent(lines[i]));
  path = path.substr(0, path.find(':'));
  std::size_t level = indent(lines[i]);
  for (std::size_t k = i; k-- > 0 && level > 0;) {
    const std::size_t in = indent(lines[k]);
    if (in == std::string::npos || in >= level) continue;
    std::string key = lines[k].substr(in);
    if (key.rfind("- ", 0) == 0) key = key.substr(2);
    path = key.substr(0, key.find(':')) + "." + path;
    level = in;
  }
  return path;
}

}  // namespace

std::string study_settings(const std::vector<RunConfig>& variants, const StepLimit& limit) {
  std::string s = "# The settings every run of this Monte Carlo directory was made with; `wingman montecarlo\n"
                  "# --resume` refuses a scenario or options that resolve differently.\n";
  s += fmt::format("duration_limit: {}\nframes_limit: {}\n",
                   limit.duration ? fmt::format("{}", *limit.duration) : "none",
                   limit.frames ? fmt::format("{}", *limit.frames) : "none");
  for (const RunConfig& v : variants) {
    s += fmt::format("--- # variant {}\n", v.variant.empty() ? v.name : v.variant);
    for (const std::string& l : lines_of(config_yaml(v)))
      if (l.rfind("#", 0) != 0 && l.rfind("seed:", 0) != 0) s += l + "\n";
  }
  return s;
}

void record_or_check_study(const fs::path& dir, const std::string& settings) {
  const fs::path file = dir / kStudySettingsFile;
  std::ifstream in(file);
  if (!in) {
    io::write_file_atomic(file, settings);
    return;
  }
  std::stringstream text;
  text << in.rdbuf();
  const auto was = lines_of(text.str()), now = lines_of(settings);
  for (std::size_t i = 0; i < std::max(was.size(), now.size()); ++i) {
    const std::string a = i < was.size() ? was[i] : "(nothing)", b = i < now.size() ? now[i] : "(nothing)";
    if (a == b) continue;
    const std::string key = i < now.size() ? key_path(now, i) : key_path(was, i);
    throw io::UsageError(fmt::format(
        "{}: its runs were made with other settings ({}, line {}: '{}'; now '{}', key {}); resume with the "
        "same scenario and options, or choose another --out",
        dir.string(), file.filename().string(), i + 1, a, b, key));
  }
}

std::string file_fnv1a64(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::uint64_t h = 0xcbf29ce484222325ull;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 0x100000001b3ull;
    }
    if (!in) break;
  }
  return fmt::format("{:016x}", h);
}

}  // namespace wingman::app
