#pragma once
// The traversability picture `plan` writes: the mission library's (run outputs draw the same),
// under the names that command uses.

#include "pitchlab/mission/traversability_image.hpp"

namespace pitchlab::apps {

using mission::RenderTraversability;
using mission::TraversabilityLegend;

}  // namespace pitchlab::apps
