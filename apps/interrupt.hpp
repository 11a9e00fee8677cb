#pragma once
// Ctrl-C and `kill` for the commands that stage their output (run, bench, map, plan): SIGINT and
// SIGTERM are taken by a watcher thread, which runs the registered cleanups (remove a staging
// folder, stop a bench's runs), says what it removed on stderr and ends the process with
// 128 + signal (130, 143). The README promises no output left behind; a signal's default action
// would leave the hidden staging folder.

#include <functional>
#include <string>

namespace pitchlab::apps {

/// Blocks SIGINT and SIGTERM in the calling thread (so in every thread started after it) and
/// starts the watcher; `command` prefixes its message ("pitchlab run"). Call before the command
/// starts any thread. Idempotent.
void InstallInterruptCleanup(const std::string& command);

/// On interruption, `cleanup(signal)` runs on the watcher thread (it may block, e.g. to wait for
/// children); when it returns true, `what` is reported as removed ("the unfinished output folder
/// 'runs/x'"). Returns an id for UnregisterCleanup. Cleanups run newest first.
int RegisterCleanup(std::function<bool(int signal)> cleanup, std::string what);
/// Forgets a cleanup (its output was committed or removed by its owner).
void UnregisterCleanup(int id);

/// When an interruption is being handled, blocks until the watcher ends the process: an error the
/// cleanup caused (a folder removed under a writer) must not become the exit status. Else returns.
void WaitIfInterrupted();

}  // namespace pitchlab::apps
