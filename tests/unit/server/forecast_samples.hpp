// The sample forecasts (grib_tools.hpp's files) read once per test program,
// and a forecast's layer by its slot.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "grib_tools.hpp"
#include "sky/server/forecast.hpp"

namespace sky::server {

inline std::shared_ptr<const Forecast> loadSample(const std::string& path) {
  static std::map<std::string, std::pair<GribFile, std::shared_ptr<const Forecast>>> cache;
  auto& slot = cache[path];
  if (!slot.second) {
    auto file = readGrib(readBytes(path), "sample", forecastWants);
    EXPECT_TRUE(file) << (file ? "" : file.error().detail);
    slot.first = std::move(*file);
    auto fc = Forecast::fromGrib({&slot.first}, path.substr(path.rfind('/') + 1));
    EXPECT_TRUE(fc) << (fc ? "" : fc.error().detail);
    slot.second = std::make_shared<const Forecast>(std::move(*fc));
  }
  return slot.second;
}

inline const ForecastLayer& layerOf(const Forecast& fc, std::uint32_t slot) {
  for (const auto& l : fc.layers())
    if (l.layer.id == slot) return l;
  ADD_FAILURE() << "no layer " << slot;
  return fc.layers().front();
}

}  // namespace sky::server
