// The `ulc` subcommands. Each lives in its own cmd_<name>.cpp and returns the process exit code:
// 0 success, 1 ran but did not succeed (the output says why), 2 bad usage or unreadable input.
#pragma once

namespace ulc::app {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;

struct Command {
  const char* name;
  const char* summary;
  int (*run)(int argc, char** argv);  ///< argv[0] is the subcommand name
};

int run_calibrate(int argc, char** argv);
int run_inspect(int argc, char** argv);
int run_evaluate(int argc, char** argv);
int run_simulate(int argc, char** argv);
int run_export(int argc, char** argv);

}  // namespace ulc::app
