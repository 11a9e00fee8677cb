#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pitchlab::worlds {

/// A world shipped with pitchlab.
struct CatalogEntry {
  std::string name;        ///< e.g. "office"
  std::string file_name;   ///< MJCF file inside the worlds folder, e.g. "office.xml"
  bool generated = false;  ///< written by pitchlab_worldgen rather than copied
};

/// The built-in worlds, in a fixed order: office, cluttered, corridor, urban, terrain, gully.
const std::vector<CatalogEntry>& BuiltinWorlds();

/// Path of a world given by catalog name (looked up in `worlds_dir`) or by a path to any .xml file.
/// Throws std::invalid_argument "unknown world 'x'; known: office, ..." for anything else, and
/// when the resolved file does not exist.
std::filesystem::path ResolveWorld(const std::string& name_or_path,
                                   const std::filesystem::path& worlds_dir);

}  // namespace pitchlab::worlds
