#pragma once

#include <filesystem>
#include <string>

#include "pitchlab/worlds/height_grid.hpp"
#include "pitchlab/worlds/world_metadata.hpp"

namespace pitchlab::worlds {

/// Writes MuJoCo's custom hfield binary: int32 nrow, int32 ncol, float32 data[nrow * ncol], with
/// MuJoCo row r = grid row iy (south to north) and column c = ix (west to east), heights relative
/// to the grid minimum (MuJoCo renormalizes to [0, 1] anyway). Throws std::runtime_error naming
/// the file when it cannot be written.
void WriteHfieldBinary(const HeightGrid& grid, const std::filesystem::path& path);

/// Writes `out_xml` (an MJCF world with one hfield geom reproducing `grid` exactly, plus the
/// metadata as custom fields) and `<stem>_hfield.bin` beside it. `comment` (e.g. the generator
/// and seed) goes into an XML comment. Throws std::runtime_error naming the file on I/O errors.
void WriteHeightfieldWorld(const HeightGrid& grid, const WorldMetadata& metadata,
                           const std::string& comment, const std::filesystem::path& out_xml);

}  // namespace pitchlab::worlds
