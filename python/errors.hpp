// Errors as Python exceptions: ulc.Error (a ValueError) carrying the line the `ulc` command
// prints for the same problem ("ulc calibrate: ..."), so a notebook and a shell say the same.
#pragma once

#include <string>
#include <utility>

#include "bindings.hpp"
#include "ulc/io/io_error.hpp"
#include "usage_error.hpp"

namespace ulc::python {

/// Raises ulc.Error with `message`.
[[noreturn]] void raise_error(const std::string& message);

/// Runs `f`, turning the command line's errors into ulc.Error with its message: a UsageError
/// already names the command ("calibrate: ..."), an io::IoError is prefixed with `command`.
template <class F>
auto with_cli_errors(const char* command, F&& f) -> decltype(f()) {
  try {
    return std::forward<F>(f)();
  } catch (const app::UsageError& e) {
    raise_error(std::string("ulc ") + e.what());
  } catch (const io::IoError& e) {
    raise_error(std::string("ulc ") + command + ": " + e.what());
  }
}

}  // namespace ulc::python
