#pragma once
// How a registration's stage timings appear in the JSON the apps write (register --json, each
// run stop's registration.json), in one place so the two read alike.

#include <nlohmann/json.hpp>

#include "pitchlab/mapping/registration.hpp"

namespace pitchlab::apps {

/// {"voxel", "normals", "features", "initial_alignment", "icp", "total"} in seconds.
inline nlohmann::json StageTimingsJson(const mapping::StageTimings& t) {
  return {{"voxel", t.voxel_s},       {"normals", t.normals_s},
          {"features", t.features_s}, {"initial_alignment", t.initial_alignment_s},
          {"icp", t.icp_s},           {"total", t.total_s}};
}

}  // namespace pitchlab::apps
