#include "interrupt.hpp"

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "ulc/io/atomic_file.hpp"

namespace ulc::app {
namespace {

/// The messages are made before any signal: the handler may only write(2) them.
char g_sigint_message[128];
char g_sigterm_message[128];
std::size_t g_sigint_length = 0, g_sigterm_length = 0;

extern "C" void on_interrupt(int signal_number) {
  io::remove_pending_temporaries();
  const bool sigint = signal_number == SIGINT;
  const ssize_t written = ::write(STDERR_FILENO, sigint ? g_sigint_message : g_sigterm_message,
                                  sigint ? g_sigint_length : g_sigterm_length);
  (void)written;  // nothing to do if stderr is gone
  ::_exit(128 + signal_number);
}

}  // namespace

void install_interrupt_handler(const char* command) {
  std::snprintf(g_sigint_message, sizeof g_sigint_message,
                "ulc %s: interrupted (SIGINT); no file left half-written\n", command);
  std::snprintf(g_sigterm_message, sizeof g_sigterm_message,
                "ulc %s: terminated (SIGTERM); no file left half-written\n", command);
  g_sigint_length = std::strlen(g_sigint_message);
  g_sigterm_length = std::strlen(g_sigterm_message);
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);  // one handler at a time
  sigaddset(&action.sa_mask, SIGTERM);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

}  // namespace ulc::app
