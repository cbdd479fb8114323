// Bad input the user can fix (a flag, a path, a variant name): one line, exit code 2.
#pragma once

#include <stdexcept>

namespace wingman::io {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace wingman::io
