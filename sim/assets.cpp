#include "sim/assets.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <stdexcept>

#include "sim/scenario.hpp"
#include "sim/yaml_input.hpp"

#ifndef WINGMAN_ASSETS_DIR
#define WINGMAN_ASSETS_DIR "assets"
#endif

namespace fs = std::filesystem;

namespace wingman::sim {

std::string assets_dir() { return WINGMAN_ASSETS_DIR; }

std::string AssetLookup::looked_text() const {
  std::string out;
  for (const auto& l : looked) out += (out.empty() ? "" : ", ") + l;
  return out;
}

AssetLookup find_asset(const std::string& path, const std::string& scenario_path) {
  const fs::path p(path);
  std::vector<fs::path> candidates;
  if (p.is_absolute()) {
    candidates.push_back(p);
  } else {
    if (!scenario_path.empty()) candidates.push_back(fs::path(scenario_path).parent_path() / p);
    candidates.push_back(fs::path(assets_dir()) / p);
  }
  AssetLookup out;
  std::error_code ec;
  for (const auto& c : candidates) {
    const std::string name = c.lexically_normal().string();
    if (fs::is_regular_file(c, ec)) {
      out.path = name;
      return out;
    }
    out.looked.push_back(name);
  }
  return out;
}

std::string resolve_asset(const std::string& path, const std::string& scenario_path,
                          const std::string& what) {
  const AssetLookup a = find_asset(path, scenario_path);
  if (a.path) return *a.path;
  throw std::runtime_error(fmt::format("{} '{}': file not found (looked at {})", what, path, a.looked_text()));
}

void check_world_files(const Scenario& s) {
  const Ctx ctx(s.source_path);
  auto check = [&](const std::string& key, const std::string& path) {
    const AssetLookup a = find_asset(path, s.source_path);
    if (a.path) return;
    YAML::Mark mark = YAML::Mark::null_mark();
    std::string where = key + " (default)";
    if (auto it = s.world_file_keys.find(key); it != s.world_file_keys.end()) {
      mark = YAML::Mark();
      mark.line = it->second.first - 1;
      mark.column = it->second.second - 1;
      where = key;
    }
    ctx.fail(mark, where, fmt::format("'{}': file not found (looked at {})", path, a.looked_text()));
  };
  if (s.world.texture.type == TextureSpec::Type::Image) check("world.texture.image", s.world.texture.image);
  check("world.lead.model", s.world.lead.model);
}

}  // namespace wingman::sim
