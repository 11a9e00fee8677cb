#include "world_paths.hpp"

#include <cstdlib>

#include "cli_args.hpp"
#include "pitchlab/worlds/world_catalog.hpp"

namespace pitchlab::apps {

std::filesystem::path WorldsDir() {
  if (const char* env = std::getenv("PITCHLAB_WORLDS_DIR"); env && *env) return env;
  return PITCHLAB_WORLDS_DIR;
}

std::string BuiltinWorldNames() {
  std::string names;
  for (const auto& entry : worlds::BuiltinWorlds()) {
    names += (names.empty() ? "" : ", ") + entry.name;
  }
  return names;
}

sim::P3Model ParseRobotModel(const std::string& name) {
  if (name == "p3at") return sim::P3Model::kP3AT;
  if (name == "p3dx") return sim::P3Model::kP3DX;
  throw CliError("'" + name + "' is not a robot (p3at, p3dx)");
}

}  // namespace pitchlab::apps
