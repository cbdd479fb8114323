// The variants of a scenario a user asked for by name (--variant), shared by the subcommands so
// that a wrong name gives the same error everywhere: the file, the name and the known variants.
#pragma once

#include <string>
#include <vector>

#include "app/config/run_config.hpp"

namespace wingman::app {

// Keeps the named variants in the order given; all of them when `names` is empty. Throws
// io::UsageError for an unknown name.
std::vector<RunConfig> select_variants(std::vector<RunConfig> scenarios,
                                           const std::vector<std::string>& names,
                                           const std::string& path);
// One variant by name, or the first one when `name` is empty.
RunConfig select_variant(std::vector<RunConfig> scenarios, const std::string& name,
                             const std::string& path);

}  // namespace wingman::app
