#pragma once
// Eq. 4-5 for one move: the single definition, evaluated once per move into
// TraversabilityGrid::move_cost, which the searches, the peer graph (ListEdges), the path's cost
// parts and EvaluatePath all read, so they agree to the last bit.

#include <cmath>

namespace pitchlab::planning {

/// Cost of moving from a cell at height za to a neighbour at zb, d_m apart in the plane [m]:
/// the neighbour's entry cost plus W_P times the 3D length P (Eq. 4; dz = 0 when either height
/// is unknown) [1].
inline double MoveCost(float enter_b, float za, float zb, double d_m, double w_length) {
  const double dz = (std::isfinite(za) && std::isfinite(zb)) ? double(zb) - za : 0.0;
  return enter_b + w_length * std::sqrt(d_m * d_m + dz * dz);  // Eq. 5 with Eq. 4's P
}

}  // namespace pitchlab::planning
