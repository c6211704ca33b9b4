// The bench's display transform against what the renderer's PNG output
// writes (sky::render::writePng, read back with stb_image), bilinear
// resampling against hand values, and contact sheet layout.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>

#include "sky/bench/contact_sheet.hpp"
#include "sky/bench/display.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::bench {
namespace {

TEST(Display, SameBytesAsTheRendererPng) {
  // Values over the whole tonemap range, below 0, and non-finite.
  render::Image img;
  img.width = 64;
  img.height = 3;
  for (std::uint32_t i = 0; i < img.width * img.height; ++i) {
    const float v = float(i) * 0.03f - 0.2f;
    img.rgba.insert(img.rgba.end(), {v, v * 0.5f, v * 2.0f, 1.0f});
  }
  img.rgba[4] = std::numeric_limits<float>::quiet_NaN();
  img.rgba[9] = std::numeric_limits<float>::infinity();
  const auto path = std::filesystem::path(testing::TempDir()) / "sky_bench_display_test.png";
  ASSERT_TRUE(render::writePng(img, path.string()));
  int w = 0, h = 0, channels = 0;
  stbi_uc* png = stbi_load(path.c_str(), &w, &h, &channels, 3);
  ASSERT_NE(png, nullptr);
  ASSERT_EQ(w, 64);
  ASSERT_EQ(h, 3);
  const Srgb8Image ours = toSrgb8({img.width, img.height, img.rgba});
  std::size_t differ = 0;
  for (std::size_t i = 0; i < ours.rgb.size(); ++i) differ += ours.rgb[i] != png[i];
  stbi_image_free(png);
  std::filesystem::remove(path);
  EXPECT_EQ(differ, 0u) << "bench display transform and renderer PNG disagree: update kDisplayExposure/toSrgb8";
}

TEST(Display, EndsOfTheRange) {
  const std::vector<float> px{0.0f, 1e6f, -3.0f, 1.0f};
  const Srgb8Image out = toSrgb8({1, 1, px});
  EXPECT_EQ(out.rgb[0], 0);
  EXPECT_EQ(out.rgb[1], 255);  // ACES saturates at 1
  EXPECT_EQ(out.rgb[2], 0);    // negative radiance clamps to black
}

TEST(Resize, HandValuesOfATwoPixelRamp) {
  // 2x1 -> 4x1: output centres map to source x = -0.25, 0.25, 0.75, 1.25,
  // clamped to [0, 1]: values 0, 0.25, 0.75, 1 of the ramp 0 -> 1.
  const std::vector<float> src{0, 0, 0, 0, 1, 2, 4, 1};
  const std::vector<float> out = resizeBilinear({2, 1, src}, 4, 1);
  ASSERT_EQ(out.size(), 16u);
  const double expected[4] = {0, 0.25, 0.75, 1};
  for (int x = 0; x < 4; ++x) {
    EXPECT_NEAR(out[std::size_t(x) * 4 + 0], expected[x], 1e-6);
    EXPECT_NEAR(out[std::size_t(x) * 4 + 2], 4 * expected[x], 1e-6);
    EXPECT_NEAR(out[std::size_t(x) * 4 + 3], expected[x], 1e-6);
  }
}

TEST(Resize, SameSizeIsIdentityAndConstantStaysConstant) {
  std::vector<float> src(5 * 4 * 4);
  for (std::size_t i = 0; i < src.size(); ++i) src[i] = float(i % 11);
  EXPECT_EQ(resizeBilinear({5, 4, src}, 5, 4), src);
  const std::vector<float> flat(3 * 2 * 4, 0.7f);
  for (float v : resizeBilinear({3, 2, flat}, 13, 9)) EXPECT_FLOAT_EQ(v, 0.7f);
}

TEST(ContactSheet, CellsKeepTheirPixels) {
  Srgb8Image a{4, 3, std::vector<std::uint8_t>(36, 200)}, b{4, 3, std::vector<std::uint8_t>(36, 90)};
  const Srgb8Image sheet = contactSheet("T", {{{&a, "A"}, {&b, "B"}}, {{&b, ""}}});
  // Layout: 6 px padding, labels 7 px + 6 px at scale 1.
  EXPECT_EQ(sheet.width, 6u + 2 * (4 + 6));
  EXPECT_EQ(sheet.height, 6u + 13 + 2 * (13 + 3 + 6));
  auto at = [&](int x, int y) { return sheet.rgb[(std::size_t(y) * sheet.width + std::size_t(x)) * 3]; };
  EXPECT_EQ(at(6, 6 + 13 + 13), 200);          // row 0, cell 0, first pixel
  EXPECT_EQ(at(6 + 10 + 3, 6 + 13 + 13 + 2), 90);  // row 0, cell 1, last pixel
  EXPECT_EQ(at(6, 6 + 13 + 22 + 13), 90);      // row 1, cell 0
}

TEST(ContactSheet, TextIsDrawnAndClipped) {
  Srgb8Image img{20, 8, std::vector<std::uint8_t>(20 * 8 * 3, 0)};
  drawText(img, 0, 0, "I", 1, {255, 255, 255});
  // 'I' has its stem in column 2 on rows 1-5 and bars on rows 0 and 6.
  EXPECT_EQ(img.rgb[(3 * 20 + 2) * 3], 255);
  EXPECT_EQ(img.rgb[(3 * 20 + 0) * 3], 0);
  drawText(img, 15, 4, "WWWW", 2, {255, 0, 0});  // runs off the right and bottom: must not write outside
  EXPECT_EQ(textWidth("WWWW", 2), 48);
}

}  // namespace
}  // namespace sky::bench
