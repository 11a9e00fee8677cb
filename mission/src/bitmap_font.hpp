#pragma once
// Text on a map picture (axis labels, scale bar, colour bar) without a font library: a 5 x 7 pixel
// font of the few characters those labels need, drawn at an integer scale.

#include <cstdint>
#include <string>

#include "pitchlab/mapping/elevation_io.hpp"

namespace pitchlab::mission {

/// Width of `text` drawn at `scale` [px]: 6 px a character (5 + 1 space) times the scale.
int TextWidth(const std::string& text, int scale);
/// Height of a line at `scale` [px].
inline int TextHeight(int scale) { return 7 * scale; }
/// True when every character of `text` is in the font: digits, space, . - + [ ] m x y z S G N.
bool FontHas(const std::string& text);
/// Draws `text` with its top-left corner at (x, y); pixels outside the picture are skipped.
/// Throws std::invalid_argument for a character the font lacks (a programming error).
void DrawText(mapping::RgbImage& image, int x, int y, const std::string& text, int scale,
              std::uint8_t r, std::uint8_t g, std::uint8_t b);

}  // namespace pitchlab::mission
