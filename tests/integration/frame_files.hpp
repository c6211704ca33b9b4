// Reading what a renderer channel writes, for the integration tests: PFM
// images (--write-float) and text files (frames.jsonl, logs, CSVs).
#pragma once

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace sky::test {

// A PFM image, top row first, `channels` floats per pixel (3 or 1).
struct Pfm {
  int width = 0, height = 0, channels = 0;
  std::vector<float> data;
  const float* at(int x, int y) const { return &data[(static_cast<std::size_t>(y) * width + x) * channels]; }
};

inline Pfm readPfm(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::string magic;
  float scale = 0;
  Pfm p;
  f >> magic >> p.width >> p.height >> scale;
  f.get();
  EXPECT_TRUE(magic == "PF" || magic == "Pf") << path;
  EXPECT_LT(scale, 0) << "little-endian PFM expected: " << path;
  p.channels = magic == "PF" ? 3 : 1;
  const std::size_t rowLen = static_cast<std::size_t>(p.width) * p.channels;
  std::vector<float> rows(rowLen * p.height);
  f.read(reinterpret_cast<char*>(rows.data()), static_cast<std::streamsize>(rows.size() * sizeof(float)));
  EXPECT_TRUE(f) << "short PFM " << path;
  p.data.resize(rows.size());
  for (int y = 0; y < p.height; ++y)  // PFM stores the bottom row first
    std::copy_n(rows.begin() + static_cast<std::ptrdiff_t>((p.height - 1 - y) * rowLen), rowLen,
                p.data.begin() + static_cast<std::ptrdiff_t>(y * rowLen));
  return p;
}

inline std::string readText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace sky::test
