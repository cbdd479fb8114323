// The `wingman` command line: subcommands wired in app/cli/commands.cpp.
#include "app/cli/commands.hpp"
#include "io/heap.hpp"

int main(int argc, char** argv) {
  wingman::io::keep_freed_memory_on_the_heap();
  return wingman::app::run_cli(argc, argv);
}
