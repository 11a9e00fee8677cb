#pragma once
// How a registration's stage timings appear in the JSON the apps write (register --json, each
// run stop's registration.json), in one place so the two read alike.

#include <cmath>

#include <nlohmann/json.hpp>

#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/mapping/registration.hpp"

namespace pitchlab::mission {

/// Rows of a 6x6 matrix (information, covariance: roll pitch yaw [rad], x y z [m]).
inline nlohmann::json Matrix6Json(const mapping::Matrix6d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 6; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 6; ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

/// The free-space evidence at a registration's pose (RegistrationResult::free_space).
inline nlohmann::json FreeSpaceJson(const mapping::RegistrationResult::FreeSpace& f) {
  return {{"source_judged", f.source_judged},
          {"source_violating", f.source_violating},
          {"target_judged", f.target_judged},
          {"target_violating", f.target_violating}};
}

/// What a registration concluded and how sure it is: outcome, covariance, the clouds' noise, the
/// length scale they resolved to and the free-space evidence at the pose.
inline nlohmann::json ObservabilityJson(const mapping::RegistrationResult& r) {
  return {{"outcome", mapping::ToString(r.outcome)},
          {"covariance", Matrix6Json(r.covariance)},
          {"covariance_order", "roll pitch yaw [rad] x y z [m], perturbation in the target frame"},
          {"noise_m", {{"source", r.source_statistics.noise_m},
                       {"target", r.target_statistics.noise_m}}},
          {"length_scale", r.settings.length_scale},
          {"free_space", FreeSpaceJson(r.free_space)}};
}

/// {"voxel", "normals", "features", "initial_alignment", "icp", "total"} in seconds.
inline nlohmann::json StageTimingsJson(const mapping::StageTimings& t) {
  return {{"voxel", t.voxel_s},       {"normals", t.normals_s},
          {"features", t.features_s}, {"initial_alignment", t.initial_alignment_s},
          {"icp", t.icp_s},           {"total", t.total_s}};
}

/// What setting a scan's lines right by its floor did (mapping::RectifyLinePitch), as register,
/// merge, map and real_eval report it: angles in degrees.
inline nlohmann::json LinePitchJson(const mapping::LinePitch& r) {
  constexpr double kToDeg = 180 / 3.14159265358979323846;
  nlohmann::json j = {{"lines", r.lines},
                      {"sweeps_per_line", r.sweeps_per_line},
                      {"corrected", r.corrected},
                      {"rms_correction_deg", r.rms_correction_rad * kToDeg},
                      {"max_correction_deg", r.max_correction_rad * kToDeg},
                      {"floor_rms_before_m", r.floor_rms_before_m},
                      {"floor_rms_after_m", r.floor_rms_after_m}};
  if (!r.note.empty()) j["note"] = r.note;
  // Each corrected line's (or sweep's) recorded pitch and turn, to the 0.001 deg: the servo's
  // error profile; with interlaced sweeps, the sweep too.
  nlohmann::json lines = nlohmann::json::array();
  const auto deg = [&](double rad) { return std::round(rad * kToDeg * 1000) / 1000; };
  for (const mapping::LineCorrection& c : r.line_corrections) {
    nlohmann::json entry = {deg(c.pitch_rad), deg(c.correction_rad)};
    if (r.sweeps_per_line > 1) entry.push_back(c.sweep);
    lines.push_back(entry);
  }
  j["pitch_and_correction_deg"] = lines;
  return j;
}

}  // namespace pitchlab::mission
