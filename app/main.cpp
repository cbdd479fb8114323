// The `wingman` command line: subcommands wired in app/commands.cpp.
#include "app/commands.hpp"

int main(int argc, char** argv) { return wingman::app::run_cli(argc, argv); }
