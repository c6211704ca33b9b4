// Lightning flashes, their light and their bolts (see lightning.hpp).
#include "sky/weather/lightning.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_map>

#include <s2/s2cell_id.h>
#include <s2/s2latlng.h>

#include "sky/core/split_mix.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::weather {

namespace {

// The share of flashes that strike the ground (in-cloud : ground near 3 : 1).
constexpr double kCloudToGroundShare = 0.25;
// Median energy of an in-cloud flash against a ground flash's
// kTypicalFlashEnergy_j, and the spread of both (log-normal, one sigma a
// factor of two): flashes differ by orders of magnitude.
constexpr double kInCloudEnergyShare = 0.5;
constexpr double kEnergyLogSigma = 0.7;
// Return strokes beyond the first: Poisson means (ground flashes have near 4
// strokes in all; in-cloud flashes a pulse or two of light), the mean gap
// between strokes and the shortest.
constexpr double kExtraStrokesGround = 2.5;
constexpr double kExtraStrokesInCloud = 1.0;
constexpr double kMeanStrokeGap_s = 0.05;
constexpr double kMinStrokeGap_s = 0.01;
// The first stroke of a flash carries twice the light of a later one.
constexpr double kFirstStrokeWeight = 2.0;
// Where in its cumulonimbus an in-cloud flash spreads: the charge layers
// between these fractions of the cloud's depth.
constexpr double kInCloudLowest = 0.35, kInCloudHighest = 0.85;
// Without a cloud to take it from (a flash asked for under a clear sky):
// a cumulonimbus from 1500 m to 10 km.
constexpr double kDefaultStormBase_m = 1500, kDefaultStormTop_m = 10000;
// A bolt leaves its cloud up to this share of its drop sideways from its
// ground point, at most this far (m): channels run mostly down, and bend at
// every scale by up to kTortuosity of the piece they split.
constexpr double kMaxBoltLeanShare = 0.4;
constexpr double kMaxBoltLean_m = 2000;
constexpr double kTortuosity = 0.18;
constexpr int kMainChannelDepth = 5;  // 2^5 = 32 segments
constexpr int kBranches = 4, kBranchSegments = 4;
constexpr double kBranchWeight = 0.3;
constexpr double kBranchSegmentShare = 0.06;  // of the channel's height, per branch segment
// Whole seconds of the clock drawn per call at most: a clock that jumped
// does not make the process draw hours of flashes at once.
constexpr double kMaxDrawSeconds = 600;
// Per cell and second: a rate above this is a storm past any real one.
constexpr double kMaxCellFlashesPerSecond = 20;

std::uint64_t mix(std::uint64_t x) { return splitMix64(x); }

// A small deterministic generator for one flash or one cell-second.
class Draws {
 public:
  explicit Draws(std::uint64_t seed) : state_(mix(seed)) {}
  std::uint64_t next() { return state_ = mix(state_); }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double normal() {
    // Box-Muller; 1 - u keeps the logarithm finite.
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
  }
  int poisson(double mean, int cap) {
    // Knuth's product of uniforms: the means here are small.
    const double limit = std::exp(-mean);
    int k = 0;
    double p = uniform();
    while (p > limit && k < cap) {
      ++k;
      p *= uniform();
    }
    return k;
  }

 private:
  std::uint64_t state_;
};

struct Stroke {
  double time_s;
  double energy_j;  // optical
};

std::vector<Stroke> strokesOf(const LightningFlash& flash) {
  Draws d(flash.seed ^ 0x5354524f4b45ull);  // "STROKE": apart from the bolt's draws
  const double extra = flash.kind == FlashKind::CloudToGround ? kExtraStrokesGround : kExtraStrokesInCloud;
  const int n = 1 + d.poisson(extra, kMaxStrokes - 1);
  // The optical energy shared by weight: the first stroke's kFirstStrokeWeight, 1 each after it.
  const double unit = flash.energy_j * kOpticalEfficiency / (kFirstStrokeWeight + (n - 1));
  std::vector<Stroke> strokes;
  double t = flash.time_s;
  for (int k = 0; k < n; ++k) {
    if (k > 0)
      t += std::min(kMaxStrokeGap_s, kMinStrokeGap_s - kMeanStrokeGap_s * std::log(1.0 - d.uniform()));
    strokes.push_back({t, unit * (k == 0 ? kFirstStrokeWeight : 1.0)});
  }
  return strokes;
}

double clampHeight(double h) { return std::clamp(h, -500.0, 20000.0); }

// The cumulonimbus weight of a tile of `layer`: its own type's share and a
// blend into cumulonimbus.
double cumulonimbusWeight(const CloudLayer& layer, const CoverageTile& tile) {
  double w = 0;
  if (layer.type == CloudType::Cumulonimbus) w += 1.0 - static_cast<double>(tile.blend);
  if (tile.blendType == CloudType::Cumulonimbus) w += static_cast<double>(tile.blend);
  return std::clamp(w, 0.0, 1.0);
}

void displace(std::vector<std::array<double, 3>>& pts, std::size_t i0, std::size_t i1, int depth, Draws& d) {
  if (depth == 0) return;
  const std::size_t mid = (i0 + i1) / 2;
  const auto& a = pts[i0];
  const auto& b = pts[i1];
  const double len = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
  const double amp = kTortuosity * len;
  pts[mid] = {(a[0] + b[0]) / 2 + amp * d.normal(), (a[1] + b[1]) / 2 + amp * d.normal(),
              (a[2] + b[2]) / 2 + 0.25 * amp * d.normal()};
  displace(pts, i0, mid, depth - 1, d);
  displace(pts, mid, i1, depth - 1, d);
}

}  // namespace

std::string_view toString(FlashKind kind) {
  return kind == FlashKind::CloudToGround ? "cloud-to-ground" : "in-cloud";
}

std::optional<FlashKind> flashKindFromString(std::string_view name) {
  if (name == "cloud-to-ground") return FlashKind::CloudToGround;
  if (name == "in-cloud") return FlashKind::InCloud;
  return std::nullopt;
}

Result<void> validate(const LightningFlash& f) {
  auto bad = [](const char* field, double v, const std::string& range) -> Result<void> {
    return fail(ErrorCode::InvalidArgument, std::string("flash: ") + field + " " + std::to_string(v) + " outside " + range);
  };
  if (!std::isfinite(f.time_s)) return bad("time_s", f.time_s, "the finite numbers");
  if (!(f.lat_deg >= -90 && f.lat_deg <= 90)) return bad("lat_deg", f.lat_deg, "[-90, 90]");
  if (!(f.lon_deg >= -180 && f.lon_deg <= 180)) return bad("lon_deg", f.lon_deg, "[-180, 180]");
  if (!(f.bottom_m >= -500 && f.bottom_m <= 20000)) return bad("bottom_m", f.bottom_m, "[-500, 20000]");
  if (!(f.top_m >= f.bottom_m && f.top_m <= 20000)) return bad("top_m", f.top_m, "[bottom_m, 20000]");
  if (!(f.energy_j > 0 && f.energy_j <= kMaxFlashEnergy_j)) return bad("energy_j", f.energy_j, "(0, 1e11]");
  if (static_cast<std::uint8_t>(f.kind) > kMaxFlashKind)
    return bad("kind", static_cast<double>(f.kind), "{0 in-cloud, 1 cloud-to-ground}");
  return {};
}

double flashPower_w(const LightningFlash& flash, double t0_s, double t1_s) {
  if (!(t1_s > t0_s) || t1_s < flash.time_s || t0_s > flash.time_s + kFlashLifetime_s) return 0;
  double energy = 0;  // optical, J, within [t0, t1]
  for (const Stroke& s : strokesOf(flash)) {
    if (t1_s <= s.time_s) continue;
    const double a = std::max(t0_s, s.time_s);
    energy += s.energy_j * (std::exp(-(a - s.time_s) / kStrokeDecay_s) - std::exp(-(t1_s - s.time_s) / kStrokeDecay_s));
  }
  return energy / (t1_s - t0_s);
}

std::vector<BoltSegment> boltSegments(const LightningFlash& flash) {
  if (flash.kind != FlashKind::CloudToGround || !(flash.top_m > flash.bottom_m)) return {};
  Draws d(flash.seed ^ 0x424f4c54ull);  // "BOLT"
  const double height = flash.top_m - flash.bottom_m;
  const double lean = std::min(kMaxBoltLean_m, kMaxBoltLeanShare * height) * std::sqrt(d.uniform()), azimuth = 2 * std::numbers::pi * d.uniform();
  constexpr std::size_t kPoints = (std::size_t(1) << kMainChannelDepth) + 1;
  std::vector<std::array<double, 3>> pts(kPoints);
  pts.front() = {lean * std::sin(azimuth), lean * std::cos(azimuth), height};
  pts.back() = {0, 0, 0};
  displace(pts, 0, kPoints - 1, kMainChannelDepth, d);
  std::vector<BoltSegment> out;
  for (std::size_t i = 0; i + 1 < kPoints; ++i)
    out.push_back({{pts[i][0], pts[i][1], pts[i][2]}, {pts[i + 1][0], pts[i + 1][1], pts[i + 1][2]}, 1.0});
  // Branches leave the upper two thirds of the channel, downwards and out.
  for (int b = 0; b < kBranches; ++b) {
    const auto start = static_cast<std::size_t>(1 + d.uniform() * (2.0 * (kPoints - 1) / 3.0));
    std::array<double, 3> p = pts[start];
    const double dir = 2 * std::numbers::pi * d.uniform();
    const double step = kBranchSegmentShare * height;
    for (int s = 0; s < kBranchSegments; ++s) {
      const double down = 0.5 + 0.4 * d.uniform();  // cosine of the piece's angle from vertical
      const double side = std::sqrt(1 - down * down);
      const double wobble = dir + 0.6 * d.normal();
      std::array<double, 3> q = {p[0] + step * side * std::sin(wobble), p[1] + step * side * std::cos(wobble),
                                 std::max(0.0, p[2] - step * down)};
      out.push_back({{p[0], p[1], p[2]}, {q[0], q[1], q[2]}, kBranchWeight});
      p = q;
    }
  }
  return out;
}

std::vector<StormCell> stormCells(const WeatherSnapshot& snapshot, std::span<const std::uint64_t> areaCells,
                                  double rate_perMin100km2) {
  if (!(rate_perMin100km2 > 0)) return {};
  std::unordered_map<std::uint64_t, StormCell> cells;
  auto add = [&](std::uint64_t cellId, const CloudLayer& l, const CoverageTile& t) {
    const double cover = static_cast<double>(t.coverage) * static_cast<double>(t.density) * cumulonimbusWeight(l, t);
    if (!(cover > 0)) return;
    const double perSecond = cover * cellArea_m2(cellId) / 1.0e8 * rate_perMin100km2 / 60.0;
    StormCell& c = cells[cellId];
    if (perSecond > c.flashesPerSecond) c = {cellId, perSecond, l.base_m, l.base_m + l.thickness_m};
  };
  for (const CloudLayer& l : snapshot.layers) {
    // As a renderer reads the snapshot: a cell's tile where it has one,
    // else the layer's own coverage and density.
    std::unordered_map<std::uint64_t, const CoverageTile*> tiles;
    for (const CoverageTile& t : snapshot.tiles)
      if (t.layerId == l.id) tiles[t.cellId] = &t;
    const CoverageTile own{0, l.id, static_cast<float>(l.coverage), static_cast<float>(l.density), CloudType::None, 0.0f};
    if (tiles.empty() && cumulonimbusWeight(l, own) == 0) continue;
    for (std::uint64_t id : areaCells) {
      const auto it = tiles.find(id);
      add(id, l, it == tiles.end() ? own : *it->second);
    }
  }
  std::vector<StormCell> out;
  out.reserve(cells.size());
  for (const auto& [id, c] : cells) out.push_back(c);
  std::sort(out.begin(), out.end(), [](const StormCell& a, const StormCell& b) { return a.cellId < b.cellId; });
  return out;
}

std::vector<LightningFlash> drawFlashes(std::uint64_t processSeed, std::span<const StormCell> cells, double from_s,
                                        double to_s, std::size_t maxFlashes, std::size_t* dropped) {
  std::vector<LightningFlash> out;
  if (dropped) *dropped = 0;
  if (!std::isfinite(from_s) || !std::isfinite(to_s) || !(to_s > from_s)) return out;
  from_s = std::max(from_s, to_s - kMaxDrawSeconds);
  const auto first = static_cast<std::int64_t>(std::floor(from_s));
  const auto last = static_cast<std::int64_t>(std::ceil(to_s)) - 1;
  for (const StormCell& cell : cells) {
    if (!(cell.flashesPerSecond > 0)) continue;
    const double rate = std::min(cell.flashesPerSecond, kMaxCellFlashesPerSecond);
    const S2CellId id(cell.cellId);
    if (!id.is_valid()) continue;
    const std::uint64_t leaves = (id.range_max().id() - id.range_min().id()) / 2 + 1;
    for (std::int64_t k = first; k <= last; ++k) {
      Draws d(processSeed ^ mix(cell.cellId ^ mix(static_cast<std::uint64_t>(k))));
      const int n = d.poisson(rate, static_cast<int>(4 * kMaxCellFlashesPerSecond));
      for (int i = 0; i < n; ++i) {
        LightningFlash f;
        f.seed = d.next();
        f.time_s = static_cast<double>(k) + d.uniform();
        const std::uint64_t leaf = id.range_min().id() + 2 * (d.next() % leaves);
        const S2LatLng ll = S2CellId(leaf).ToLatLng();
        f.lat_deg = ll.lat().degrees();
        f.lon_deg = ll.lng().degrees();
        f.kind = d.uniform() < kCloudToGroundShare ? FlashKind::CloudToGround : FlashKind::InCloud;
        const double median = kTypicalFlashEnergy_j * (f.kind == FlashKind::InCloud ? kInCloudEnergyShare : 1.0);
        f.energy_j = std::min(kMaxFlashEnergy_j, median * std::exp(kEnergyLogSigma * d.normal()));
        const double depth = std::max(0.0, cell.top_m - cell.base_m);
        if (f.kind == FlashKind::CloudToGround) {
          f.bottom_m = 0;
          f.top_m = clampHeight(std::max(0.0, cell.base_m));
        } else {
          f.bottom_m = clampHeight(cell.base_m + kInCloudLowest * depth);
          f.top_m = clampHeight(cell.base_m + kInCloudHighest * depth);
        }
        if (f.time_s > from_s && f.time_s <= to_s) out.push_back(f);
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const LightningFlash& a, const LightningFlash& b) {
    return a.time_s != b.time_s ? a.time_s < b.time_s : a.seed < b.seed;
  });
  if (out.size() > maxFlashes) {
    if (dropped) *dropped = out.size() - maxFlashes;
    out.resize(maxFlashes);
  }
  return out;
}

LightningFlash triggeredFlash(std::uint64_t seed, double time_s, double lat_deg, double lon_deg, FlashKind kind,
                              std::span<const CloudLayer> layers, double energy_j) {
  double base = kDefaultStormBase_m, top = kDefaultStormTop_m;
  const CloudLayer* pick = nullptr;
  for (const CloudLayer& l : layers) {
    if (l.type == CloudType::Fog || isPrecipitation(l.type)) continue;
    const bool better = !pick || (l.type == CloudType::Cumulonimbus && pick->type != CloudType::Cumulonimbus) ||
                        (l.type == pick->type && l.base_m < pick->base_m) ||
                        (pick->type != CloudType::Cumulonimbus && l.base_m < pick->base_m);
    if (better) pick = &l;
  }
  if (pick) {
    base = pick->base_m;
    top = pick->base_m + pick->thickness_m;
  }
  LightningFlash f;
  f.seed = mix(seed);
  f.time_s = time_s;
  f.lat_deg = lat_deg;
  f.lon_deg = lon_deg;
  f.kind = kind;
  f.energy_j = energy_j;
  if (kind == FlashKind::CloudToGround) {
    f.bottom_m = 0;
    f.top_m = clampHeight(std::max(0.0, base));
  } else {
    f.bottom_m = clampHeight(base + kInCloudLowest * (top - base));
    f.top_m = clampHeight(base + kInCloudHighest * (top - base));
  }
  return f;
}

}  // namespace sky::weather
