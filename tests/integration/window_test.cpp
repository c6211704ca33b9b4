// skyshell-render --window under a real X server (Xvfb on a free display):
// a flight replayed into a GLFW window through a Vulkan swapchain, with
// Khronos validation on. Every frame is presented, the validation layer
// reports no error, and what the X server holds in the window (read back by
// xwd, independent of the renderer) is exactly the PNG of one of the frames.
// Skipped when Xvfb or the validation layer is missing.
#include <cstdio>
#include <cstdlib>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <stb_image.h>

#include "child_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr int kWidth = 160, kHeight = 90;
// 0..6 s of the test flight, one frame per second, shown at flight pace: a
// 6 s run, long enough to look at the window while it runs.
constexpr std::size_t kFrames = 7;
constexpr const char* kValidationLayerJson = "/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json";

std::optional<fs::path> onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return fs::path(dir) / program;
  return std::nullopt;
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t lines(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty();
  return n;
}

// An XWD file (X11 window dump, as written by xwd: header in big-endian
// CARD32s, pixels in the server's byte order) as 8-bit RGB.
struct Capture {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
};

std::optional<Capture> readXwd(const std::string& bytes) {
  auto be32 = [&](std::size_t at) {
    return (std::uint32_t(std::uint8_t(bytes[at])) << 24) | (std::uint32_t(std::uint8_t(bytes[at + 1])) << 16) |
           (std::uint32_t(std::uint8_t(bytes[at + 2])) << 8) | std::uint32_t(std::uint8_t(bytes[at + 3]));
  };
  if (bytes.size() < 100) return std::nullopt;
  const std::uint32_t headerSize = be32(0), version = be32(4), format = be32(8), width = be32(16), height = be32(20),
                      byteOrder = be32(28), bitsPerPixel = be32(44), bytesPerLine = be32(48), redMask = be32(56),
                      greenMask = be32(60), blueMask = be32(64), colours = be32(76);
  // Version 7, ZPixmap, 32 bits per pixel: what a 24-bit TrueColor Xvfb gives.
  if (version != 7 || format != 2 || bitsPerPixel != 32) return std::nullopt;
  const std::size_t pixels = std::size_t(headerSize) + std::size_t(colours) * 12;
  if (bytes.size() < pixels + std::size_t(bytesPerLine) * height) return std::nullopt;
  auto channel = [](std::uint32_t v, std::uint32_t mask) {
    int shift = 0;
    while (mask && !(mask & 1u)) mask >>= 1, ++shift;
    return std::uint8_t((v >> shift) & mask);
  };
  Capture c;
  c.width = int(width);
  c.height = int(height);
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      const std::size_t at = pixels + std::size_t(y) * bytesPerLine + std::size_t(x) * 4;
      std::uint32_t v = 0;
      for (int b = 0; b < 4; ++b) {
        const std::uint32_t byte = std::uint8_t(bytes[at + std::size_t(b)]);
        v |= byteOrder == 0 ? byte << (8 * b) : byte << (8 * (3 - b));
      }
      c.rgb.push_back(channel(v, redMask));
      c.rgb.push_back(channel(v, greenMask));
      c.rgb.push_back(channel(v, blueMask));
    }
  return c;
}

TEST(WindowedRender, PresentsEveryFrameWithoutValidationErrors) {
  const auto xvfb = onPath("Xvfb");
  if (!xvfb) GTEST_SKIP() << "Xvfb is not installed (Debian: xvfb)";
  if (!fs::exists(kValidationLayerJson)) GTEST_SKIP() << "no Vulkan validation layer (Debian: vulkan-validationlayers)";
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "window";
  fs::remove_all(dir);
  fs::create_directories(dir);

  // -displayfd 1: the server picks a free display and prints its number.
  ChildProcess x({xvfb->string(), "-displayfd", "1", "-screen", "0", "320x240x24", "-nolisten", "tcp", "-noreset"},
                 (dir / "xvfb.log").string());
  std::string display;
  for (auto until = std::chrono::steady_clock::now() + 30s; display.empty() && std::chrono::steady_clock::now() < until;) {
    std::istringstream log(x.log());
    for (std::string line; std::getline(log, line);)
      if (!line.empty() && line.find_first_not_of("0123456789") == std::string::npos) display = ":" + line;
    if (display.empty()) std::this_thread::sleep_for(50ms);
  }
  ASSERT_FALSE(display.empty()) << "Xvfb did not say its display:\n" << x.log();

  const fs::path out = dir / "out";
  ChildProcess render({SKY_RENDER, "--window", "--headless", "--vulkan-validation", "--replay", SKY_TEST_FLIGHT,
                       "--weather-file", SKY_SCENARIO_CLOUDY, "--step", "1", "--replay-pace", "1", "--no-video",
                       "--no-exr", "--out", out.string(), "--width", std::to_string(kWidth), "--height",
                       std::to_string(kHeight)},
                      (dir / "render.log").string(),
                      {"DISPLAY=" + display, "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});

  // While it runs: dump the window from the X server once two frames are up.
  std::vector<Capture> captures;
  const auto xwd = onPath("xwd");
  if (xwd) {
    for (auto until = std::chrono::steady_clock::now() + 120s;
         lines(out / "frames" / "frames.jsonl") < 2 && std::chrono::steady_clock::now() < until;)
      std::this_thread::sleep_for(50ms);
    for (int attempt = 0; attempt < 3; ++attempt) {
      const fs::path dump = dir / ("window-" + std::to_string(attempt) + ".xwd");
      ChildProcess grab({xwd->string(), "-display", display, "-name", "skyshell-render", "-silent", "-out",
                         dump.string()},
                        (dir / "xwd.log").string());
      if (grab.wait(30s).value_or(-1) != 0) continue;
      if (auto c = readXwd(readAll(dump))) captures.push_back(std::move(*c));
      std::this_thread::sleep_for(300ms);
    }
  }

  const auto code = render.wait(300s);
  const std::string log = render.log();
  ASSERT_EQ(code.value_or(-1), 0) << log;
  EXPECT_NE(log.find("vulkan validation on"), std::string::npos) << log;
  EXPECT_NE(log.find("vulkan validation: 0 errors"), std::string::npos) << log;
  EXPECT_EQ(log.find("vulkan validation error"), std::string::npos) << log;

  const auto report = nlohmann::json::parse(readAll(out / "report.json"));
  EXPECT_EQ(report["frames"], kFrames);
  EXPECT_EQ(report["frames_presented"], kFrames);
  std::vector<std::vector<std::uint8_t>> pngs;
  std::ifstream jsonl(out / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);) {
    const auto f = nlohmann::json::parse(line);
    EXPECT_EQ(f["presented"], true) << line;
    ASSERT_TRUE(f["gpu_ms"].contains("present")) << line;
    EXPECT_GT(f["gpu_ms"]["present"].get<double>(), 0.0) << line;
    int w = 0, h = 0, n = 0;
    const std::string bytes = readAll(out / "frames" / f["file"].get<std::string>());
    unsigned char* rgb = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()),
                                               &w, &h, &n, 3);
    ASSERT_NE(rgb, nullptr);
    pngs.emplace_back(rgb, rgb + std::size_t(w) * h * 3);
    stbi_image_free(rgb);
  }
  EXPECT_EQ(pngs.size(), kFrames);

  if (!xwd) {
    std::printf("[ note     ] xwd not installed (Debian: x11-apps): the window's pixels were not compared\n");
    return;
  }
  ASSERT_FALSE(captures.empty()) << "xwd could not dump the window: " << readAll(dir / "xwd.log");
  bool matched = false;
  for (const Capture& c : captures) {
    EXPECT_EQ(c.width, kWidth);
    EXPECT_EQ(c.height, kHeight);
    for (const auto& png : pngs) matched = matched || c.rgb == png;
  }
  EXPECT_TRUE(matched) << "none of " << captures.size() << " window dumps equals a frame's PNG";
}

}  // namespace
}  // namespace sky::test
