#pragma once
// A planned path as files: CSV, GeoJSON in WGS84 (GeographicLib), and drawn on the map picture.

#include <optional>
#include <string>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/planning/planner.hpp"

namespace pitchlab::planning {

/// CSV with a header: index,x_m,y_m,z_m,cum_length_m (z empty in unknown cells), map frame.
/// Written atomically; an error names the path. A waypoint without a finite x, y, or a non-finite
/// cost or length, is an error (kInvalidArgument) and nothing is written.
[[nodiscard]] Result<void> WritePathCsv(const Path& path, const std::string& file);

/// GeoJSON FeatureCollection: one LineString of [lon, lat, height] (WGS84 [deg], ellipsoidal
/// height [m]) with the cost, its parts, length, max step and inclination as properties. Where a
/// waypoint's height is unknown (its cell unobserved) the positions are [lon, lat] and the
/// property `heights` is false: path.csv has the heights that are known. The map
/// frame is a local ENU frame at `origin` (GeographicLib::LocalCartesian). Fails
/// (kInvalidArgument) without a geodetic origin, or as WritePathCsv on non-finite values; a
/// non-finite property is written as null, so the file is always valid JSON.
[[nodiscard]] Result<void> WritePathGeoJson(const Path& path,
                                            const std::optional<mapping::GeodeticOrigin>& origin,
                                            const std::string& file);

/// Draws the path (a 2 px red line, start green, goal blue) on a picture rendered from a map of
/// `geometry` by mapping::RenderElevationImage.
void DrawPath(const Path& path, const mapping::GridGeometry& geometry, mapping::RgbImage& image);

}  // namespace pitchlab::planning
