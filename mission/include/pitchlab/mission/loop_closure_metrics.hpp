#pragma once
// metrics.json's "loop_closures" for a mission run with loop closure on (run: {loop_closure:
// true}): MapBuilder's loop edges tried, accepted and refused, and the accepted ones scored
// against the truth (issue 20: a wrong one is more than 0.1 m or 1 deg off the true relative
// pose, mapping::IsWrongLoopClosure). Kept apart from the rest of metrics.json.

#include <nlohmann/json.hpp>

#include "pitchlab/mission/mission.hpp"

namespace pitchlab::mission {

/// {registered, registration_failed, accepted, rejected, wrong, edges: [{from_stop, to_stop,
/// translation_error_m, rotation_error_deg, wrong}]}: `wrong` and the errors null where a stop of
/// the edge has no truth (hardware). Throws std::logic_error when an edge names a scan no merged
/// stop holds (MapBuilder and the stops out of step: a bug).
nlohmann::json LoopClosureJson(const MissionResult& result);

}  // namespace pitchlab::mission
