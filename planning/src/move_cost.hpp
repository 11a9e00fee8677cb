#pragma once
// Eq. 4-5 for one move: the single definition. BuildTraversability stores it for every allowed
// move (TraversabilityGrid::move_cost); the cost of a move that is not allowed (a path costed on
// another map) is evaluated on demand by the same function, so all agree to the last bit.

#include <cstddef>

#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::planning {

/// Eq. 4-5 cost of move b (kMoveDi/kMoveDj) out of cell k, whether allowed or not, rounded to
/// float as stored in move_cost; +inf when the neighbour is off the grid [1]. Reads z_m and
/// enter_cost only.
float MoveCostOf(const TraversabilityGrid& grid, std::size_t k, int b);

}  // namespace pitchlab::planning
