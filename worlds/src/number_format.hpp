#pragma once

#include <string>

namespace pitchlab::worlds {

/// `value` in fixed notation with `decimals` digits, "-0" normalized to "0": locale-free and
/// identical on every run, so generated MJCF is reproducible byte for byte.
std::string FormatFixed(double value, int decimals);

}  // namespace pitchlab::worlds
