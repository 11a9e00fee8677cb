#pragma once
// Round tick positions and their labels, shared by the PNG map figures and the SVG plots.

#include <string>
#include <vector>

namespace pitchlab::mission {

/// A round step for about `count` ticks over `span`: 1, 2 or 5 times a power of ten.
double NiceStep(double span, int count);
/// The multiples of `step` in [lo, hi] (exact zero where one falls on it).
std::vector<double> Ticks(double lo, double hi, double step);
/// `v` with no more decimals than `step` needs and no "-0".
std::string TickLabel(double v, double step);

}  // namespace pitchlab::mission
