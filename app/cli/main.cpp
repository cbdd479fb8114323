// The `wingman` command line: subcommands wired in app/cli/commands.cpp.
#include "app/cli/commands.hpp"

int main(int argc, char** argv) { return wingman::app::run_cli(argc, argv); }
