// Contact sheets of the bench: rows of labelled images (a configuration, the
// reference, the error heat map) on one page, with a built-in 5x7 bitmap font
// for the labels so no font file or library is needed.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sky/bench/metrics.hpp"

namespace sky::bench {

// One labelled image. The pointer must outlive the contactSheet call.
struct SheetCell {
  const Srgb8Image* image = nullptr;
  std::string label;
};

// A page with a title line, then one row per entry of `rows`, cells left to
// right, each cell its label above its image. Cells are as wide and tall as
// the largest image; smaller images sit top-left on the dark background.
Srgb8Image contactSheet(std::string_view title, const std::vector<std::vector<SheetCell>>& rows);

// Draws text with its top-left corner at (x, y), each font pixel a scale x
// scale square; letters are drawn upper case, characters without a glyph as
// a box; whatever falls outside the image is clipped.
void drawText(Srgb8Image& image, int x, int y, std::string_view text, int scale, std::array<std::uint8_t, 3> colour);

// Width and height in pixels of the text drawn at this scale.
inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphAdvance = 6;  // font pixels
inline int textWidth(std::string_view text, int scale) { return int(text.size()) * kGlyphAdvance * scale; }

}  // namespace sky::bench
