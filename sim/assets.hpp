// Files a scenario's world section names (the ground image, the lead's model): where a relative
// path is looked up, and the check that they exist, done when a scenario is loaded to be rendered
// so that a missing file is bad input naming the scenario's line, not a failure mid-run.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace wingman::sim {

struct Scenario;

// The repository's assets/ folder (set at build time).
std::string assets_dir();

// A path as found: the file, or every place looked at.
struct AssetLookup {
  std::optional<std::string> path;
  std::vector<std::string> looked;
  std::string looked_text() const;  // "a, b"
};
// An absolute path as it is; a relative one next to the scenario file, then in assets_dir().
AssetLookup find_asset(const std::string& path, const std::string& scenario_path);
// Same; throws std::runtime_error "<what> '<path>': file not found (looked at ...)" when missing.
std::string resolve_asset(const std::string& path, const std::string& scenario_path,
                          const std::string& what);

// Every file the world section names that rendering would read (world.texture.image when the
// texture is an image, world.lead.model) must exist; throws ScenarioError naming the scenario
// file, the key's line and column (or "(default)") and the places looked at.
void check_world_files(const Scenario& s);

}  // namespace wingman::sim
