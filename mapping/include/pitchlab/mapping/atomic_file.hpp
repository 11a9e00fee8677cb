#pragma once
// Files written whole or not at all: to a temporary name beside the target, then renamed over it.
// Every map, raster, trajectory and path pitchlab writes goes through here.

#include <string>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Writes `bytes` to `path` atomically: on failure (a full disk, no permission) the temporary file
/// is removed and `path` is as it was. Errors name the path and the reason.
[[nodiscard]] Result<void> WriteFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace pitchlab::mapping
