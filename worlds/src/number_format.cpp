#include "number_format.hpp"

#include <cstdio>

namespace pitchlab::worlds {

std::string FormatFixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  std::string text(buffer);
  // "-0.000" and "0.000" are the same number; print it one way.
  if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) text.erase(0, 1);
  return text;
}

}  // namespace pitchlab::worlds
