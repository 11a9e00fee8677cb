#pragma once
// Fixture for the layering check's own test: sensors may not include sim, so this must be flagged.
#include "pitchlab/sim/simulation.hpp"
