#include "app/commands.hpp"

#include <CLI/CLI.hpp>

#include "app/version.hpp"

namespace wingman::app {
int run_cli(int argc, char** argv) {
  CLI::App cli{"wingman: cooperative visual SLAM for UAV teams flying with a lead agent"};
  cli.set_version_flag("--version", kVersion);
  CLI11_PARSE(cli, argc, argv);
  return 0;
}
}  // namespace wingman::app
