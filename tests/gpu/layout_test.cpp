// The uniform layout pinned twice (STYLE.md): sky_shared.h's static_asserts pin
// the C++ side; this test compares the offsets glslang reports for the
// compiled shader (glslangValidator -q) with the C++ offsetof values.
#include <array>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "sky_shared.h"

namespace {

using sky::gpu::SkyCloudType;
using sky::gpu::SkyFrame;
using sky::gpu::SkyLayer;

std::string reflect() {
  const std::string cmd = std::string(SKY_GLSLANG) + " --target-env vulkan1.2 " + SKY_SHADER_INCLUDE_FLAGS + " -q " +
                          SKY_SHADER_SOURCE_DIR + "/clouds.comp 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  if (!pipe) return out;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), int(buf.size()), pipe.get()) != nullptr) out += buf.data();
  return out;
}

TEST(SharedLayout, GlslangOffsetsMatchCpp) {
  const std::string text = reflect();
  ASSERT_NE(text.find("Uniform reflection"), std::string::npos) << text;

  constexpr std::size_t layers = offsetof(SkyFrame, layers);
  const std::map<std::string, std::size_t> expected = {
      {"frame.camForward", offsetof(SkyFrame, camForward)},
      {"frame.camRight", offsetof(SkyFrame, camRight)},
      {"frame.camDown", offsetof(SkyFrame, camDown)},
      {"frame.localToEcef", offsetof(SkyFrame, localToEcef)},
      {"frame.camToAnchor", offsetof(SkyFrame, camToAnchor)},
      {"frame.camInAnchor", offsetof(SkyFrame, camInAnchor)},
      {"frame.weatherMap", offsetof(SkyFrame, weatherMap)},
      {"frame.earth", offsetof(SkyFrame, earth)},
      {"frame.sunDir", offsetof(SkyFrame, sunDir)},
      {"frame.sunIrradiance", offsetof(SkyFrame, sunIrradiance)},
      {"frame.groundIrradiance", offsetof(SkyFrame, groundIrradiance)},
      {"frame.image", offsetof(SkyFrame, image)},
      {"frame.dispatch", offsetof(SkyFrame, dispatch)},
      {"frame.weatherRings", offsetof(SkyFrame, weatherRings)},
      {"frame.layers.heights", layers + offsetof(SkyLayer, heights)},
      {"frame.layers.shape", layers + offsetof(SkyLayer, shape)},
      {"frame.layers.shapeOrigin", layers + offsetof(SkyLayer, shapeOrigin)},
      {"frame.layers.detailOrigin", layers + offsetof(SkyLayer, detailOrigin)},
      {"frame.layers.cloudMapOrigin", layers + offsetof(SkyLayer, cloudMapOrigin)},
      {"frame.layers.coverageShift", layers + offsetof(SkyLayer, coverageShift)},
      {"frame.layers.ambient", layers + offsetof(SkyLayer, ambient)},
      {"frame.layers.sunDiffuse", layers + offsetof(SkyLayer, sunDiffuse)},
      {"frame.layers.band", layers + offsetof(SkyLayer, band)},
      {"frame.layers.primary.a", layers + offsetof(SkyLayer, primary) + offsetof(SkyCloudType, a)},
      {"frame.layers.primary.d", layers + offsetof(SkyLayer, primary) + offsetof(SkyCloudType, d)},
      {"frame.layers.secondary.a", layers + offsetof(SkyLayer, secondary) + offsetof(SkyCloudType, a)},
      {"frame.layers.secondary.d", layers + offsetof(SkyLayer, secondary) + offsetof(SkyCloudType, d)},
      {"frame.steps", offsetof(SkyFrame, steps)},
      {"frame.flashInfo", offsetof(SkyFrame, flashInfo)},
      {"frame.flashes", offsetof(SkyFrame, flashes)},
      {"frame.boltStart", offsetof(SkyFrame, boltStart)},
      {"frame.boltEnd", offsetof(SkyFrame, boltEnd)},
  };
  // Lines look like "frame.layers.shape: offset 288, type 8b52, ..., topLevelArrayStride 80".
  std::map<std::string, std::size_t> seen;
  std::size_t blockSize = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto colon = line.find(": offset ");
    if (colon == std::string::npos) continue;
    const std::string name = line.substr(0, colon);
    if (name == "FrameBlock") {
      const auto size = line.find(", size ");
      if (size != std::string::npos) blockSize = std::stoul(line.substr(size + 7));
      continue;
    }
    if (name.rfind("frame.", 0) != 0) continue;
    seen[name] = std::stoul(line.substr(colon + 9));
    const auto stride = line.find("topLevelArrayStride ");
    if (name.rfind("frame.layers.", 0) == 0 && stride != std::string::npos) {
      EXPECT_EQ(std::stoul(line.substr(stride + 20)), sizeof(SkyLayer)) << name;
    }
  }
  for (const auto& [name, offset] : expected) {
    // glslang lists only members the shader uses; every one of ours is used.
    ASSERT_TRUE(seen.count(name)) << name << " missing from glslang's reflection:\n" << text;
    EXPECT_EQ(seen[name], offset) << name;
  }
  EXPECT_EQ(blockSize, sizeof(SkyFrame));
}

}  // namespace
