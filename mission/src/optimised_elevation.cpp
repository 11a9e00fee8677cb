#include "optimised_elevation.hpp"

#include <stdexcept>

namespace pitchlab::mission {

mapping::ElevationMap OptimisedElevation::Map() const {
  mapping::ElevationMap map = scans_.map();
  for (const mapping::ElevationMap& view : views_) {
    const auto merged = map.Merge(view, mapping::ElevationMap::MergeCells::kUnknown);
    // ViewOver aligns every view to the map's cells: a failure is a bug.
    if (!merged) throw std::logic_error("optimised elevation: " + merged.error().message);
  }
  return map;
}

}  // namespace pitchlab::mission
