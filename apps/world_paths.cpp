#include "world_paths.hpp"

#include <cstdlib>
#include <system_error>

#include "cli_args.hpp"
#include "pitchlab/worlds/world_catalog.hpp"

namespace pitchlab::apps {

std::filesystem::path WorldsDir() {
  if (const char* env = std::getenv("PITCHLAB_WORLDS_DIR"); env && *env) return env;
  // An installed pitchlab: <prefix>/bin/pitchlab finds <prefix>/share/pitchlab/worlds. The build
  // tree's program has no such folder beside it and uses the build's worlds.
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed = exe.parent_path() / PITCHLAB_WORLDS_FROM_BIN;
    if (std::filesystem::is_directory(installed, ec)) return installed.lexically_normal();
  }
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
