#pragma once
// Ctrl-C and `kill` for the commands that stage their output (run, bench, map, plan): SIGINT and
// SIGTERM are taken by a watcher thread, which runs the cleanups registered with the mission
// library (mission::RegisterCleanup: remove a staging folder, stop a bench's runs), says what it
// removed on stderr and ends the process with 128 + signal (130, 143). The README promises no
// output left behind; a signal's default action would leave the hidden staging folder.

#include <string>

namespace pitchlab::apps {

/// Blocks SIGINT and SIGTERM in the calling thread (so in every thread started after it) and
/// starts the watcher; `command` prefixes its message ("pitchlab run"). Call before the command
/// starts any thread. Idempotent.
void InstallInterruptCleanup(const std::string& command);

}  // namespace pitchlab::apps
