#pragma once
// Fixture for the layering check: planning may include only mapping, never the closed loop.
#include "pitchlab/mission/mission.hpp"
