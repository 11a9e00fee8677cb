#pragma once
// Where the app finds worlds, and the small name <-> enum mappings every subcommand shares.

#include <filesystem>
#include <string>

#include "pitchlab/sim/robot_model.hpp"

namespace pitchlab::apps {

/// The worlds folder: $PITCHLAB_WORLDS_DIR if set, else the installed worlds beside the program
/// (<prefix>/share/pitchlab/worlds), else the build's generated worlds.
std::filesystem::path WorldsDir();
/// "office, cluttered, ..." for help texts and errors.
std::string BuiltinWorldNames();
/// "p3at" / "p3dx" -> model; CliError otherwise.
sim::P3Model ParseRobotModel(const std::string& name);

}  // namespace pitchlab::apps
