// Cloud type names and layer validation.
#include "sky/weather/model.hpp"

#include <array>
#include <cmath>
#include <string>

namespace sky::weather {

namespace {
constexpr std::array<std::string_view, kMaxCloudType + 1> kNames = {
    "none",       "altocumulus",  "altostratus",  "cirrocumulus",  "cirrostratus", "cirrus",
    "cumulonimbus", "cumulus",    "nimbostratus", "stratocumulus", "stratus"};

Result<void> checkRange(const CloudLayer& layer, const char* field, double value, double lo,
                        double hi, bool openLow = false) {
  const bool ok = std::isfinite(value) && (openLow ? value > lo : value >= lo) && value <= hi;
  if (ok) return {};
  return fail(ErrorCode::InvalidArgument,
              "layer " + std::to_string(layer.id) + ": " + field + " " + std::to_string(value) +
                  " outside " + (openLow ? "(" : "[") + std::to_string(lo) + ", " +
                  std::to_string(hi) + "]");
}
}  // namespace

std::string_view toString(CloudType type) {
  const auto i = static_cast<std::size_t>(type);
  return i < kNames.size() ? kNames[i] : std::string_view("unknown");
}

std::optional<CloudType> cloudTypeFromString(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return static_cast<CloudType>(i);
  return std::nullopt;
}

Result<void> validate(const CloudLayer& layer) {
  if (static_cast<std::uint8_t>(layer.type) > kMaxCloudType)
    return fail(ErrorCode::InvalidArgument,
                "layer " + std::to_string(layer.id) + ": cloud type " +
                    std::to_string(static_cast<int>(layer.type)) + " outside [0, 10]");
  Result<void> r;
  if (!(r = checkRange(layer, "base_m", layer.base_m, -500, 20000))) return r;
  if (!(r = checkRange(layer, "thickness_m", layer.thickness_m, 0, 20000, true))) return r;
  if (!(r = checkRange(layer, "transition_band_m", layer.transitionBand_m, 0, 5000))) return r;
  if (!(r = checkRange(layer, "coverage", layer.coverage, 0, 1))) return r;
  if (!(r = checkRange(layer, "density", layer.density, 0, 1))) return r;
  if (!(r = checkRange(layer, "wind.speed_mps", layer.wind.speed_mps, 0, 150))) return r;
  if (!(r = checkRange(layer, "wind.from_deg", layer.wind.fromDirection_deg, 0, 360))) return r;
  if (!(r = checkRange(layer, "wind.vertical_mps", layer.wind.vertical_mps, -50, 50))) return r;
  return {};
}

}  // namespace sky::weather
