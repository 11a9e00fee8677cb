#pragma once
// Files written whole or not at all: to a temporary name beside the target, then renamed.

#include <string>

#include "pitchlab/mapping/elevation_map.hpp"  // Result

namespace pitchlab::planning {

/// Writes `bytes` to `file` atomically; on failure (a full disk) no partial file is left. Errors
/// name the file.
[[nodiscard]] Result<void> WriteFileAtomically(const std::string& file, const std::string& bytes);

}  // namespace pitchlab::planning
