// Lightning: flashes as events on the weather clock. The server draws them
// from a seeded process over the storm cells of the areas its renderers
// watch and streams them; every channel then lights the same flash at the
// same moment, and each flash's strokes and bolt follow from its seed alone
// (lightFlashPower, boltSegments), so two renderers draw the same bolt.
//
// The numbers are round climatological values, not measurements of ours:
// * an ordinary thunderstorm of ~100 km^2 flashes one to a few times a
//   minute (kDefaultFlashRate_perMin100km2: 1 at full cumulonimbus cover of
//   density 1; denser storms flash more, in proportion);
// * about a quarter of flashes strike the ground (the global mean ratio of
//   in-cloud to cloud-to-ground flashes is near 3);
// * a cloud-to-ground flash dissipates of the order of 1 GJ, and radiates
//   about 1 % of it as light (kOpticalEfficiency); it has a few return
//   strokes (mean near 4) some 60 ms apart, whose light decays over tens of
//   milliseconds (kStrokeDecay_s, the glow of the continuing current).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "sky/weather/model.hpp"

namespace sky::weather {

enum class FlashKind : std::uint8_t {
  InCloud = 0,
  CloudToGround = 1,
};
inline constexpr std::uint8_t kMaxFlashKind = 1;
std::string_view toString(FlashKind kind);  // "in-cloud", "cloud-to-ground"
std::optional<FlashKind> flashKindFromString(std::string_view name);

struct LightningFlash {
  std::uint64_t seed = 0;  // names the flash; its strokes and bolt follow from it
  double time_s = 0;       // weather clock of its first stroke
  double lat_deg = 0;      // geodetic: a bolt's ground point, an in-cloud flash's centre
  double lon_deg = 0;
  double bottom_m = 0;     // MSL: the bolt's foot (the ground), or the in-cloud flash's lowest point
  double top_m = 0;        // MSL: where the bolt leaves the cloud (its base), or the flash's highest point
  FlashKind kind = FlashKind::InCloud;
  double energy_j = 0;     // dissipated, (0, kMaxFlashEnergy_j]
  bool operator==(const LightningFlash&) const = default;
};

inline constexpr double kMaxFlashEnergy_j = 1.0e11;
inline constexpr double kTypicalFlashEnergy_j = 1.0e9;
inline constexpr double kOpticalEfficiency = 0.01;
inline constexpr double kStrokeDecay_s = 0.03;
// How long after its first stroke a flash can still give light: the last
// stroke (at most kMaxStrokes, kMaxStrokeGap_s apart) plus ten decays.
inline constexpr int kMaxStrokes = 8;
inline constexpr double kMaxStrokeGap_s = 0.15;
inline constexpr double kFlashLifetime_s = kMaxStrokes * kMaxStrokeGap_s + 10 * kStrokeDecay_s;

// Range checks for a flash from outside (a stream message, an API call):
// finite, latitude and longitude in range, bottom <= top within the model's
// heights, energy in (0, kMaxFlashEnergy_j]. The error names the field.
Result<void> validate(const LightningFlash& flash);

// The mean optical power (W) a flash radiates over the weather-clock
// interval [t0_s, t1_s] (t1 > t0: a frame's exposure), from its strokes:
// each stroke's light jumps up and decays with kStrokeDecay_s, and their
// energies sum to energy_j x kOpticalEfficiency. 0 before the flash and
// after kFlashLifetime_s.
double flashPower_w(const LightningFlash& flash, double t0_s, double t1_s);

// A straight piece of a bolt's channel in the local east-north-up frame of
// the flash's ground point (metres), with its share of the light (the main
// channel 1, branches less).
struct BoltSegment {
  double a[3] = {0, 0, 0};
  double b[3] = {0, 0, 0};
  double weight = 1;
};
inline constexpr std::size_t kMaxBoltSegments = 48;
// The channel of a cloud-to-ground flash from its top (the cloud base,
// offset horizontally by up to 0.4 of the drop and 2 km) down to its ground point, tortuous at every scale
// (midpoint displacement), with a few branches that stop short of the
// ground; at most kMaxBoltSegments, the main channel's first. Empty for an
// in-cloud flash. A function of the flash alone.
std::vector<BoltSegment> boltSegments(const LightningFlash& flash);

// A storm cell: one S2 cell of an area with its cumulonimbus, for the flash
// process.
struct StormCell {
  std::uint64_t cellId = 0;
  double flashesPerSecond = 0;
  double base_m = 0, top_m = 0;  // the cumulonimbus there
};
inline constexpr double kDefaultFlashRate_perMin100km2 = 1.0;
// Storm cells among areaCells (S2 cells at the snapshot's tile level, the
// area's covering), each read as a renderer reads the snapshot (its tile,
// or the layer's own coverage and density where it has none): where a layer
// is cumulonimbus (its own type, or a tile's blend into it), coverage x
// density x that weight x the cell's area x rate_perMin100km2 flashes a
// minute (the heaviest layer per cell). Cells with none are left out.
std::vector<StormCell> stormCells(const WeatherSnapshot& snapshot, std::span<const std::uint64_t> areaCells,
                                  double rate_perMin100km2);

// The flashes of the seeded process over `cells` with first strokes in the
// weather-clock interval (from_s, to_s]. Each whole second of the clock in
// each cell draws its own Poisson count from (processSeed, cell, second),
// so the flashes of an interval do not depend on how it is cut into calls,
// and two servers with one seed and the same storms draw the same flashes.
// At most maxFlashes (the earliest) are returned; `dropped` counts the rest.
std::vector<LightningFlash> drawFlashes(std::uint64_t processSeed, std::span<const StormCell> cells,
                                        double from_s, double to_s, std::size_t maxFlashes,
                                        std::size_t* dropped = nullptr);

// A flash the operator asked for at (lat, lon) at time_s: of `kind`, under
// the cumulonimbus (or, with none, the lowest cloud) of `layers` there, with
// the given seed (the server's count of such flashes, mixed).
LightningFlash triggeredFlash(std::uint64_t seed, double time_s, double lat_deg, double lon_deg, FlashKind kind,
                              std::span<const CloudLayer> layers, double energy_j = kTypicalFlashEnergy_j);

}  // namespace sky::weather
