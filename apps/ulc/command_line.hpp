// The `ulc` commands parse their options with CLI11 (Debian's libcli11-dev): each builds a
// CLI::App named "ulc <command>", declares its options with their defaults, checks and help, and
// calls parse_command_line. What CLI11 refuses (unknown option, missing value, value out of
// range, required option missing) becomes a UsageError: one line, exit code 2.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "usage_error.hpp"

namespace ulc::app {

/// Parses argv (argv[0] is the command's name). Returns true when --help was asked for and
/// printed (the command then exits with 0); bad usage throws UsageError "<command>: <problem>".
inline bool parse_command_line(CLI::App& app, const std::string& command, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return false;
  } catch (const CLI::CallForHelp&) {
    std::printf("%s", app.help().c_str());
    return true;
  } catch (const CLI::ParseError& e) {
    throw UsageError(command + ": " + e.what() + " (see `ulc " + command + " --help`)");
  }
}

}  // namespace ulc::app
