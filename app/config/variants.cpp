#include "app/config/variants.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "io/usage_error.hpp"

namespace wingman::app {

std::vector<RunConfig> select_variants(std::vector<RunConfig> scenarios,
                                           const std::vector<std::string>& names,
                                           const std::string& path) {
  if (names.empty()) return scenarios;
  std::vector<RunConfig> keep;
  for (const auto& name : names) {
    auto it = std::find_if(scenarios.begin(), scenarios.end(),
                           [&](const RunConfig& s) { return s.variant == name; });
    if (it == scenarios.end()) {
      std::string known;
      for (const auto& s : scenarios) known += (known.empty() ? "" : ", ") + s.variant;
      throw io::UsageError(fmt::format("{}: no variant '{}' (variants: {})", path, name,
                                   known.empty() ? "none" : known));
    }
    keep.push_back(*it);
  }
  return keep;
}

RunConfig select_variant(std::vector<RunConfig> scenarios, const std::string& name,
                             const std::string& path) {
  if (name.empty()) return scenarios.front();
  return select_variants(std::move(scenarios), {name}, path).front();
}

}  // namespace wingman::app
