// Bad usage of a `ulc` command: an option the command line parser refused, or a combination or
// value the command itself refuses. main() prints "ulc <what>" and exits with code 2.
#pragma once

#include <stdexcept>

namespace ulc::app {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace ulc::app
