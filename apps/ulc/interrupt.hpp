// Ctrl-C and SIGTERM: every `ulc` command stops at once, whatever it is computing, and leaves no
// half-written file. The pipeline has no cancellation points inside its long loops, so the
// handler does not ask it to stop: it removes the temporaries being written
// (io::remove_pending_temporaries; every output is written through io::AtomicFile), prints one
// line on stderr and calls _exit(128 + signal number): 130 for SIGINT, 143 for SIGTERM. Files
// already complete stay; no file is ever left half-written.
#pragma once

namespace ulc::app {

/// Installs the handler for SIGINT and SIGTERM; `command` names the command in its message.
void install_interrupt_handler(const char* command);

}  // namespace ulc::app
