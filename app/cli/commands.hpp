// Entry point of the `wingman` command line and its subcommands.
#pragma once

namespace wingman::app {
// Parses argv, runs the chosen subcommand and returns the process exit code
// (0 ok, 1 runtime failure, 2 bad input such as a malformed scenario or bad flags).
int run_cli(int argc, char** argv);
}  // namespace wingman::app
