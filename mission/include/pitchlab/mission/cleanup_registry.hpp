#pragma once
// What a process must undo when it is interrupted: a RunFolder registers its hidden staging
// folder here, so that Ctrl-C leaves no half-written output. The library only keeps the list; the
// program that owns the signals (the pitchlab command's watcher thread) runs it and ends.

#include <functional>
#include <string>
#include <vector>

namespace pitchlab::mission {

/// `cleanup(signal)` runs on interruption (it may block, e.g. to wait for children); when it
/// returns true, `what` is reported as removed ("the unfinished output folder 'runs/x'").
/// Returns an id for UnregisterCleanup. Thread-safe.
int RegisterCleanup(std::function<bool(int signal)> cleanup, std::string what);
/// Forgets a cleanup (its output was committed or removed by its owner). Unknown ids are ignored.
void UnregisterCleanup(int id);

/// For a program about to end on `signal`: marks the process interrupted and runs every
/// registered cleanup, newest first. Returns the `what` of each cleanup that returned true.
std::vector<std::string> RunCleanups(int signal);

/// Once RunCleanups has started, blocks for good (the program that called it is ending the
/// process): an error the cleanup caused, a folder removed under a writer, must not become the
/// exit status. Else returns at once.
void WaitIfInterrupted();

}  // namespace pitchlab::mission
