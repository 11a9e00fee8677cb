#include "pitchlab/worlds/world_catalog.hpp"

#include <stdexcept>

namespace pitchlab::worlds {

const std::vector<CatalogEntry>& BuiltinWorlds() {
  static const std::vector<CatalogEntry> kWorlds = {
      {"office", "office.xml", false},     {"cluttered", "cluttered.xml", false},
      {"corridor", "corridor.xml", false}, {"urban", "urban.xml", false},
      {"terrain", "terrain.xml", true},    {"gully", "gully.xml", true},
  };
  return kWorlds;
}

std::filesystem::path ResolveWorld(const std::string& name_or_path,
                                   const std::filesystem::path& worlds_dir) {
  for (const CatalogEntry& entry : BuiltinWorlds()) {
    if (entry.name != name_or_path) continue;
    const std::filesystem::path path = worlds_dir / entry.file_name;
    if (!std::filesystem::exists(path)) {
      throw std::invalid_argument("world '" + name_or_path + "': " + path.string() +
                                  " does not exist (build the target pitchlab_world_files)");
    }
    return path;
  }
  const std::filesystem::path path(name_or_path);
  if (path.extension() == ".xml") {
    if (!std::filesystem::exists(path)) {
      throw std::invalid_argument("world file '" + name_or_path + "' does not exist");
    }
    return path;
  }
  std::string known;
  for (const CatalogEntry& entry : BuiltinWorlds()) {
    known += (known.empty() ? "" : ", ") + entry.name;
  }
  throw std::invalid_argument("unknown world '" + name_or_path + "'; known: " + known);
}

}  // namespace pitchlab::worlds
