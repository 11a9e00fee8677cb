#pragma once
// Ctrl-C for the hardware layer. SIGINT / SIGTERM only set a flag (async-signal-safe); every
// driver's wait loop polls it and returns an "interrupted" error within one read timeout, and the
// caller then unwinds normally so the drivers' destructors leave the devices safe (base stopped
// and motors disabled, LMS200 output stopped). No device I/O ever happens inside the handler.

#include <string>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::hw {

/// Makes SIGINT and SIGTERM request a stop (without SA_RESTART, so blocking calls wake up).
/// Idempotent.
void InstallStopSignalHandlers();
/// True once a stop was requested (by a signal or RequestStop).
bool StopRequested();
/// The signal that requested the stop (SIGINT, SIGTERM), 0 when none did.
int StopSignal();
/// Requests a stop as the signal `signal` would (0: without a signal).
void RequestStop(int signal = 0);
/// Forgets a stop request (a new session in the same process, tests).
void ClearStopRequest();
/// "interrupted by SIGINT" (or SIGTERM, or "a stop request").
std::string StopReason();
/// The error a driver returns when a stop was requested: kFailed, naming `device` and the signal.
Error StopError(const std::string& device);
/// Exit status of a process ended by the stop request: 128 + signal (130 for SIGINT), else 1.
int StopExitCode();

}  // namespace pitchlab::hw
