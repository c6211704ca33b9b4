// The headless replay's outputs that need no GPU: which frames a contact sheet
// shows, how it shrinks them, and the report's percentiles; and its input's
// bound (readFile, which reads a flight file at most kMaxFlightFileBytes).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sky/app/fallback_weather.hpp"
#include "sky/app/replay_outputs.hpp"

namespace sky::app {
namespace {

render::Image uniform(std::uint32_t w, std::uint32_t h, float v) {
  render::Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(std::size_t(w) * h * 4, v);
  return img;
}

TEST(ContactSheet, PicksEvenlyIncludingFirstAndLast) {
  EXPECT_EQ(ContactSheet::pick(100, 12).front(), 0u);
  EXPECT_EQ(ContactSheet::pick(100, 12).back(), 99u);
  EXPECT_EQ(ContactSheet::pick(100, 12).size(), 12u);
  // 0, 9, 18, ... (99 / 11 = 9 exactly).
  EXPECT_EQ(ContactSheet::pick(100, 12)[1], 9u);
  EXPECT_EQ(ContactSheet::pick(5, 12), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(ContactSheet::pick(1, 12), (std::vector<std::size_t>{0}));
  EXPECT_TRUE(ContactSheet::pick(0, 12).empty());
}

TEST(ContactSheet, CellsAreBoxFilteredFramesBetweenGaps) {
  // 2 x 1 cells of 8 px width from 16 x 8 frames: cells 8 x 4, gaps of 4.
  ContactSheet sheet(2, 1, 8, 16, 8);
  const auto& img = sheet.image();
  EXPECT_EQ(img.width, 2u * (8 + 4) + 4);
  EXPECT_EQ(img.height, 1u * (4 + 4) + 4);
  // A frame whose left half is 0 and right half 1: the cell's left half 0, right half 1.
  render::Image half = uniform(16, 8, 0.0f);
  for (std::uint32_t y = 0; y < 8; ++y)
    for (std::uint32_t x = 8; x < 16; ++x)
      for (int c = 0; c < 4; ++c) half.rgba[(std::size_t(y) * 16 + x) * 4 + std::size_t(c)] = 1.0f;
  sheet.add(half);
  // A frame with a NaN pixel: it is left out of its box, not spread.
  render::Image withNan = uniform(16, 8, 0.5f);
  withNan.rgba[0] = std::numeric_limits<float>::quiet_NaN();
  sheet.add(withNan);
  sheet.add(uniform(16, 8, 9.0f));  // beyond the 2 cells: ignored
  auto at = [&](std::uint32_t x, std::uint32_t y) { return img.rgba[(std::size_t(y) * img.width + x) * 4]; };
  EXPECT_FLOAT_EQ(at(4, 4), 0.0f);       // first cell, left half
  EXPECT_FLOAT_EQ(at(4 + 7, 4), 1.0f);   // first cell, right half
  EXPECT_FLOAT_EQ(at(16, 4), 0.5f);      // second cell's first pixel: its NaN skipped
  EXPECT_FLOAT_EQ(at(16 + 7, 7), 0.5f);
  EXPECT_FLOAT_EQ(at(0, 0), 0.02f);      // the gap
  EXPECT_FLOAT_EQ(at(12 + 1, 4), 0.02f); // between the cells
  for (float v : img.rgba) EXPECT_TRUE(std::isfinite(v));
}

TEST(Percentiles, NearestRank) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // unsorted on purpose
  const Percentiles p = percentiles(v);
  EXPECT_EQ(p.p50, 50);
  EXPECT_EQ(p.p90, 90);
  EXPECT_EQ(p.p99, 99);
  EXPECT_EQ(p.max, 100);
  EXPECT_DOUBLE_EQ(p.mean, 50.5);
  EXPECT_EQ(percentiles({}).p50, 0);
  EXPECT_EQ(percentiles({7}).p99, 7);
}

// A file of exactly the bound is read; one byte more is refused with its
// name, having read no further than the bound plus one byte.
TEST(ReadFile, RefusesAFileLargerThanItsBound) {
  const auto path = std::filesystem::temp_directory_path() / "sky-readfile-bound.csv";
  std::ofstream(path, std::ios::binary) << "0123456789";
  const auto exact = readFile(path.string(), 10);
  ASSERT_TRUE(exact);
  EXPECT_EQ(*exact, "0123456789");
  const auto over = readFile(path.string(), 9);
  ASSERT_FALSE(over);
  EXPECT_EQ(over.error().code, ErrorCode::TooLarge);
  EXPECT_NE(over.error().detail.find("sky-readfile-bound.csv: larger than 9 bytes"), std::string::npos)
      << over.error().detail;
  // The default, no bound (SIZE_MAX: "bound + 1" must not wrap to a read of 0 bytes, forever).
  const auto unbounded = readFile(path.string());
  ASSERT_TRUE(unbounded);
  EXPECT_EQ(unbounded->size(), 10u);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sky::app
