// Contact sheet composition and the 5x7 label font (contact_sheet.hpp).
#include "sky/bench/contact_sheet.hpp"

#include <algorithm>
#include <cctype>

namespace sky::bench {

namespace {

// One glyph: 7 rows, bit 4 is the leftmost of 5 columns.
struct Glyph {
  char c;
  std::array<std::uint8_t, 7> rows;
};

// Drawn for this file: capitals, digits and the punctuation the bench's labels use.
constexpr std::array<Glyph, 50> kFont{{
    {'A', {0b01110, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001}},
    {'B', {0b11110, 0b10001, 0b10001, 0b11110, 0b10001, 0b10001, 0b11110}},
    {'C', {0b01110, 0b10001, 0b10000, 0b10000, 0b10000, 0b10001, 0b01110}},
    {'D', {0b11110, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b11110}},
    {'E', {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111}},
    {'F', {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b10000}},
    {'G', {0b01110, 0b10001, 0b10000, 0b10111, 0b10001, 0b10001, 0b01111}},
    {'H', {0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001}},
    {'I', {0b01110, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'J', {0b00111, 0b00010, 0b00010, 0b00010, 0b00010, 0b10010, 0b01100}},
    {'K', {0b10001, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010, 0b10001}},
    {'L', {0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b11111}},
    {'M', {0b10001, 0b11011, 0b10101, 0b10101, 0b10001, 0b10001, 0b10001}},
    {'N', {0b10001, 0b10001, 0b11001, 0b10101, 0b10011, 0b10001, 0b10001}},
    {'O', {0b01110, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'P', {0b11110, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000, 0b10000}},
    {'Q', {0b01110, 0b10001, 0b10001, 0b10001, 0b10101, 0b10010, 0b01101}},
    {'R', {0b11110, 0b10001, 0b10001, 0b11110, 0b10100, 0b10010, 0b10001}},
    {'S', {0b01111, 0b10000, 0b10000, 0b01110, 0b00001, 0b00001, 0b11110}},
    {'T', {0b11111, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100}},
    {'U', {0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'V', {0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100}},
    {'W', {0b10001, 0b10001, 0b10001, 0b10101, 0b10101, 0b10101, 0b01010}},
    {'X', {0b10001, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001, 0b10001}},
    {'Y', {0b10001, 0b10001, 0b01010, 0b00100, 0b00100, 0b00100, 0b00100}},
    {'Z', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b11111}},
    {'0', {0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110}},
    {'1', {0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'2', {0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111}},
    {'3', {0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110}},
    {'4', {0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010}},
    {'5', {0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110}},
    {'6', {0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110}},
    {'7', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000}},
    {'8', {0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110}},
    {'9', {0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100}},
    {' ', {0, 0, 0, 0, 0, 0, 0}},
    {'.', {0, 0, 0, 0, 0, 0b01100, 0b01100}},
    {',', {0, 0, 0, 0, 0b01100, 0b00100, 0b01000}},
    {'-', {0, 0, 0, 0b11111, 0, 0, 0}},
    {'_', {0, 0, 0, 0, 0, 0, 0b11111}},
    {'=', {0, 0, 0b11111, 0, 0b11111, 0, 0}},
    {':', {0, 0b01100, 0b01100, 0, 0b01100, 0b01100, 0}},
    {'/', {0, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0}},
    {'%', {0b11000, 0b11001, 0b00010, 0b00100, 0b01000, 0b10011, 0b00011}},
    {'(', {0b00010, 0b00100, 0b01000, 0b01000, 0b01000, 0b00100, 0b00010}},
    {')', {0b01000, 0b00100, 0b00010, 0b00010, 0b00010, 0b00100, 0b01000}},
    {'+', {0, 0b00100, 0b00100, 0b11111, 0b00100, 0b00100, 0}},
    {'>', {0b01000, 0b00100, 0b00010, 0b00001, 0b00010, 0b00100, 0b01000}},
    {'<', {0b00010, 0b00100, 0b01000, 0b10000, 0b01000, 0b00100, 0b00010}},
}};

// Drawn for characters without a glyph.
constexpr std::array<std::uint8_t, 7> kBox{0b11111, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b11111};

const std::array<std::uint8_t, 7>& glyphOf(char c) {
  const char upper = char(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kFont)
    if (g.c == upper) return g.rows;
  return kBox;
}

void putPixel(Srgb8Image& image, int x, int y, std::array<std::uint8_t, 3> colour) {
  if (x < 0 || y < 0 || x >= int(image.width) || y >= int(image.height)) return;
  std::copy(colour.begin(), colour.end(), image.rgb.begin() + (std::ptrdiff_t(y) * image.width + x) * 3);
}

constexpr std::array<std::uint8_t, 3> kBackground{24, 24, 28};
constexpr std::array<std::uint8_t, 3> kLabelColour{235, 235, 235};
constexpr int kPad = 6;  // px around cells and labels

}  // namespace

void drawText(Srgb8Image& image, int x, int y, std::string_view text, int scale, std::array<std::uint8_t, 3> colour) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto& rows = glyphOf(text[i]);
    const int left = x + int(i) * kGlyphAdvance * scale;
    for (int r = 0; r < kGlyphHeight; ++r)
      for (int col = 0; col < kGlyphWidth; ++col)
        if (rows[std::size_t(r)] & (1u << (kGlyphWidth - 1 - col)))
          for (int dy = 0; dy < scale; ++dy)
            for (int dx = 0; dx < scale; ++dx) putPixel(image, left + col * scale + dx, y + r * scale + dy, colour);
  }
}

Srgb8Image contactSheet(std::string_view title, const std::vector<std::vector<SheetCell>>& rows) {
  std::uint32_t cellW = 1, cellH = 1;
  std::size_t columns = 1;
  for (const auto& row : rows) {
    columns = std::max(columns, row.size());
    for (const auto& cell : row)
      if (cell.image) cellW = std::max(cellW, cell.image->width), cellH = std::max(cellH, cell.image->height);
  }
  // Labels at twice the font size once a cell is wide enough to hold them.
  const int scale = cellW >= 256 ? 2 : 1;
  const int labelH = kGlyphHeight * scale + kPad;
  const int rowH = labelH + int(cellH) + kPad;
  Srgb8Image sheet;
  sheet.width = std::uint32_t(kPad + int(columns) * (int(cellW) + kPad));
  sheet.height = std::uint32_t(kPad + labelH + int(rows.size()) * rowH);
  sheet.rgb.resize(std::size_t(sheet.width) * sheet.height * 3);
  for (std::size_t p = 0; p < std::size_t(sheet.width) * sheet.height; ++p)
    std::copy(kBackground.begin(), kBackground.end(), sheet.rgb.begin() + std::ptrdiff_t(p * 3));
  drawText(sheet, kPad, kPad, title, scale, kLabelColour);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      const SheetCell& cell = rows[r][c];
      const int x0 = kPad + int(c) * (int(cellW) + kPad);
      const int y0 = kPad + labelH + int(r) * rowH;
      drawText(sheet, x0, y0, cell.label.substr(0, std::size_t(cellW) / std::size_t(kGlyphAdvance * scale)), scale,
               kLabelColour);
      if (!cell.image) continue;
      const Srgb8Image& img = *cell.image;
      for (std::uint32_t y = 0; y < img.height && y * img.width * 3 < img.rgb.size(); ++y)
        std::copy_n(img.rgb.begin() + std::ptrdiff_t(y) * img.width * 3, img.width * 3,
                    sheet.rgb.begin() + (std::ptrdiff_t(y0 + labelH + int(y)) * sheet.width + x0) * 3);
    }
  return sheet;
}

}  // namespace sky::bench
