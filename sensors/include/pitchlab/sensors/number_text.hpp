#pragma once
// Numbers in messages as people write them: std::to_string(0.1) is "0.100000", and an error
// saying "within 0.500000..4.000000 m" reads like a dump, not a sentence.

#include <cstdio>
#include <string>

namespace pitchlab {

/// `v` with up to 6 significant digits and no trailing zeros (printf's %g): 0.1 -> "0.1",
/// 4.0 -> "4", 93.1234567 -> "93.1235", 1e-7 -> "1e-07", NaN -> "nan".
inline std::string NumberText(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace pitchlab
