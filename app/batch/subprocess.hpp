// Running a client command (sbatch, squeue) to its end and capturing what it prints.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace wingman::app {

struct ProcessOutput {
  int exit_code = -1;  // -1 when a signal ended it
  std::string out, err;
};

// Runs argv (argv[0] looked up on PATH) with stdin from /dev/null, in its own process group so
// that the terminal's Ctrl-C cannot cut a submission half-way. Throws std::runtime_error when it
// cannot be started.
ProcessOutput run_process(const std::vector<std::string>& argv);

// The executable `name` as found on PATH, or an empty path.
std::filesystem::path find_on_path(const std::string& name);

}  // namespace wingman::app
