// `ulc`: the command-line front end. Dispatches to a subcommand and turns exceptions into one
// clear line on stderr and an exit code (docs/design.md, "The command line").
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "commands.hpp"
#include "interrupt.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/version.hpp"
#include "usage_error.hpp"

namespace {

constexpr ulc::app::Command kCommands[] = {
    {"calibrate", "find the extrinsic of target LiDARs against a base LiDAR, with no guess",
     ulc::app::run_calibrate},
    {"simulate", "write a simulated multi-LiDAR dataset with exact ground truth",
     ulc::app::run_simulate},
    {"inspect", "print what a cloud file, a frame folder or a recording (bag) holds",
     ulc::app::run_inspect},
    {"export", "write LiDARs of a recording (bag) as a dataset folder of PCD frames",
     ulc::app::run_export},
    {"evaluate", "compare a result file with ground truth (e_rot, e_trans, time offset)",
     ulc::app::run_evaluate},
};

void print_usage(std::FILE* to) {
  std::fprintf(to,
               "ulc %s: universal LiDAR-to-LiDAR calibration\n\nusage: ulc <command> "
               "[options]\n\ncommands:\n",
               ULC_VERSION_STRING);
  for (const auto& c : kCommands) std::fprintf(to, "  %-12s %s\n", c.name, c.summary);
  std::fprintf(to, "\n`ulc <command> --help` describes a command's options.\n");
}

/// glibc hands buffers above its mmap threshold (dynamic, from 128 KiB) straight to the kernel
/// and returns freed heap tops to it, so every frame's thinned copies, kd-trees and plane lists
/// come back as fresh pages: about a million page faults on the 60 s 64-32 drive, 9 s of system
/// time. Keeping up to 256 MiB of freed memory and serving buffers below 32 MiB (glibc's
/// largest threshold) from the heap halves them with the same peak memory
/// (docs/experiments/sixty_second_drive_speed.md). Other allocators ignore this.
void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory();
  if (argc < 2) {
    print_usage(stderr);
    return ulc::app::kExitUsage;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(stdout);
    return ulc::app::kExitOk;
  }
  if (name == "--version") {
    std::printf("ulc %s\n", ULC_VERSION_STRING);
    return ulc::app::kExitOk;
  }
  for (const auto& c : kCommands) {
    if (name != c.name) continue;
    ulc::app::install_interrupt_handler(c.name);
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const ulc::app::UsageError& e) {
      std::fprintf(stderr, "ulc %s\n", e.what());
      return ulc::app::kExitUsage;
    } catch (const ulc::io::IoError& e) {
      std::fprintf(stderr, "ulc %s: %s\n", c.name, e.what());
      return ulc::app::kExitUsage;
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "ulc %s: out of memory\n", c.name);
      return ulc::app::kExitFailed;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ulc %s: %s\n", c.name, e.what());
      return ulc::app::kExitFailed;
    }
  }
  std::fprintf(stderr, "ulc: unknown command '%s' (try `ulc --help`)\n", name.c_str());
  return ulc::app::kExitUsage;
}
