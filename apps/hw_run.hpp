#pragma once
// `pitchlab run --backend hw` (or a config with `backend: hw`): the arguments of a closed-loop run
// on the real devices and its lines. The run itself is mission::RunHwMission (hw_mission.hpp).

#include "pitchlab/mission/hw_mission.hpp"

namespace pitchlab::apps {

/// The backend `pitchlab run` was asked for: `--backend` if given, else the `--config` file's
/// `backend`. Throws CliError on a bad --backend and std::invalid_argument on a bad config.
mission::Backend SelectedBackend(int argc, char** argv);

/// `pitchlab run --backend hw`: the whole run (arguments after "run"); exit code as RunRun, or
/// hw::StopExitCode() when a signal stopped it.
int RunHwRun(int argc, char** argv);

}  // namespace pitchlab::apps
