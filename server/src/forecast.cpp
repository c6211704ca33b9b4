// GRIB2 fields to cloud layers (forecast.hpp).
#include "sky/server/forecast.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "forecast_axes.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// GRIB2 code table 4.5: level types of cloud layers and their limits.
constexpr long kCloudBase = 2, kCloudTop = 3, kIsobaric = 100, kHeightAboveGround = 103;
constexpr long kBoundaryLayerCloud = 211, kLowCloud = 214, kMiddleCloud = 224, kHighCloud = 234,
               kConvectiveCloud = 244;
// Bottom and top of the low, middle, high and convective layers (212/213 ...).
constexpr long kLowBottom = 212, kLowTop = 213, kMiddleBottom = 222, kMiddleTop = 223, kHighBottom = 232,
               kHighTop = 233, kConvectiveBottom = 242, kConvectiveTop = 243;
// Code table 4.2: discipline 0 categories and numbers read.
constexpr long kCatTemperature = 0, kCatMoisture = 1, kCatMomentum = 2, kCatMass = 3, kCatCloud = 6;
constexpr long kTotalCloudCover = 1, kLowCloudCover = 3, kMediumCloudCover = 4, kHighCloudCover = 5;
constexpr long kRelativeHumidity = 1, kPressure = 0, kGeopotentialHeight = 5;
constexpr long kSurface = 1, kPrecipitationRate = 7;
// NCEP's local categorical precipitation types (0 or 1 per point).
constexpr long kCategoricalRain = 192, kCategoricalFreezingRain = 193, kCategoricalIcePellets = 194,
               kCategoricalSnow = 195;

// Sundqvist et al. (1989, Mon. Wea. Rev. 117) diagnose cloud from relative
// humidity above a critical value; 0.8 is the middle of the 0.75-0.85 range
// models use for it.
constexpr double kCriticalHumidity = 0.8;
// The layer limits of NCEP's Unified Post Processor (PTOP_LOW, PTOP_MID):
// low cloud below 642 hPa, middle to 350 hPa, high above.
constexpr double kLowTop_pa = 64200, kMiddleTop_pa = 35000;
// A grid point counts as cloudy for a layer's median height above this cover.
constexpr float kCloudyCover = 0.1f;
// The convective layer turns from cumulus to cumulonimbus between these
// covers: GFS's convective cover is small for shallow convection and grows
// with organised deep convection. A choice, not a measurement.
constexpr float kCbFrom = 0.3f, kCbFull = 0.7f;

struct SlotDefaults {
  std::uint32_t id;
  weather::CloudType type;
  double base_m, thickness_m;
  const char* name;
};
// Typical heights (MSL) of each family when a file says nothing of them.
constexpr SlotDefaults kSlots[] = {
    {kForecastBoundarySlot, weather::CloudType::Stratocumulus, 500, 700, "boundary layer"},
    {kForecastLowSlot, weather::CloudType::Stratocumulus, 1000, 1500, "low"},
    {kForecastMiddleSlot, weather::CloudType::Altocumulus, 3600, 1800, "middle"},
    {kForecastHighSlot, weather::CloudType::Cirrus, 8000, 1500, "high"},
    {kForecastConvectiveSlot, weather::CloudType::Cumulus, 1200, 5000, "convective"},
    {kForecastPrecipitationSlot, weather::CloudType::Rain, 0, 2000, "precipitation"},
};
// The precipitation layer reaches this far (m) into the lowest cloud layer.
constexpr double kPrecipitationIntoCloud_m = 500;

const SlotDefaults& slotDefaults(std::uint32_t id) {
  for (const auto& s : kSlots)
    if (s.id == id) return s;
  return kSlots[1];
}

std::optional<std::uint32_t> coverSlot(const GribMeta& m) {
  if (m.discipline != 0 || m.category != kCatCloud) return std::nullopt;
  if (m.number == kTotalCloudCover) {
    switch (m.levelType) {
      case kBoundaryLayerCloud: return kForecastBoundarySlot;
      case kLowCloud: return kForecastLowSlot;
      case kMiddleCloud: return kForecastMiddleSlot;
      case kHighCloud: return kForecastHighSlot;
      case kConvectiveCloud: return kForecastConvectiveSlot;
      default: return std::nullopt;
    }
  }
  if (m.number == kLowCloudCover) return kForecastLowSlot;
  if (m.number == kMediumCloudCover) return kForecastMiddleSlot;
  if (m.number == kHighCloudCover) return kForecastHighSlot;
  return std::nullopt;
}

// The slot whose bottom (true) or top (false) a layer-limit level type is.
std::optional<std::pair<std::uint32_t, bool>> limitSlot(long levelType) {
  switch (levelType) {
    case kLowBottom: return std::pair{kForecastLowSlot, true};
    case kLowTop: return std::pair{kForecastLowSlot, false};
    case kMiddleBottom: return std::pair{kForecastMiddleSlot, true};
    case kMiddleTop: return std::pair{kForecastMiddleSlot, false};
    case kHighBottom: return std::pair{kForecastHighSlot, true};
    case kHighTop: return std::pair{kForecastHighSlot, false};
    case kConvectiveBottom: return std::pair{kForecastConvectiveSlot, true};
    case kConvectiveTop: return std::pair{kForecastConvectiveSlot, false};
    default: return std::nullopt;
  }
}

// Cover as a fraction: % by the message's units (or, with no units, by its
// values' range).
float coverScale(const GribField& f) {
  if (f.meta.units == "%") return 0.01f;
  if (f.meta.units.find("0 - 1") != std::string::npos) return 1.0f;
  float hi = 0;
  for (float v : f.values)
    if (v > hi) hi = v;
  return hi > 1.5f ? 0.01f : 1.0f;
}

std::string describe(const GribField& f) {
  return f.meta.shortName + " " + f.meta.typeOfLevel + ", field " + std::to_string(f.meta.field);
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Fields of one valid time, by what they are.
struct StepFields {
  std::map<std::uint32_t, const GribField*> cover;                  // by slot
  std::map<std::pair<std::uint32_t, bool>, const GribField*> limit;  // (slot, bottom) -> pressure
  std::map<double, const GribField*> humidity, height;               // isobaric, by Pa
  const GribField* cloudBaseHeight = nullptr;
  const GribField* cloudBasePressure = nullptr;
  const GribField* precipitationRate = nullptr;
  std::map<long, const GribField*> categorical;  // by parameter number (192-195)
};

// The precipitation rate of a step as a grid (mm/h), and its points' votes
// for a type from the categorical fields on the same grid.
std::shared_ptr<CoverGrid> precipitationGrid(const StepFields& s, std::map<weather::CloudType, std::size_t>& votes) {
  const GribField& f = *s.precipitationRate;
  auto g = std::make_shared<CoverGrid>();
  g->grid = f.meta.grid;
  g->source = describe(f);
  g->fraction.resize(f.values.size());
  auto flagged = [&](long number, std::size_t k) {
    const auto it = s.categorical.find(number);
    return it != s.categorical.end() && it->second->meta.grid == g->grid && k < it->second->values.size() &&
           it->second->values[k] > 0.5f;
  };
  for (std::size_t k = 0; k < f.values.size(); ++k) {
    const float v = f.values[k];
    g->fraction[k] = std::isnan(v) ? kNaN : std::max(0.0f, v * 3600.0f);  // kg m-2 s-1 = mm/s
    if (!(g->fraction[k] >= kMinForecastPrecipitation_mmph)) continue;
    if (flagged(kCategoricalSnow, k)) ++votes[weather::CloudType::Snow];
    else if (flagged(kCategoricalIcePellets, k) || flagged(kCategoricalFreezingRain, k)) ++votes[weather::CloudType::Sleet];
    else ++votes[weather::CloudType::Rain];
  }
  return g;
}

// Sundqvist cover per grid point for the pressure band (lo_pa, hi_pa], with
// the heights of the lowest and highest cloudy level per point.
struct Derived {
  std::shared_ptr<CoverGrid> cover;
  std::vector<double> bases_m, tops_m;  // over cloudy points
};

Derived deriveBand(const StepFields& s, double lo_pa, double hi_pa, const std::string& band) {
  Derived d;
  std::vector<std::pair<double, const GribField*>> levels;
  for (const auto& [p, f] : s.humidity)
    if (p > lo_pa && p <= hi_pa) levels.emplace_back(p, f);
  if (levels.empty()) return d;
  const GribGrid& grid = levels.front().second->meta.grid;
  for (const auto& [p, f] : levels)
    if (!(f->meta.grid == grid)) return d;  // levels on different grids: not derived
  std::sort(levels.begin(), levels.end(), [](const auto& a, const auto& b) { return a.first > b.first; });  // upwards
  auto cover = std::make_shared<CoverGrid>();
  cover->grid = grid;
  const std::size_t n = static_cast<std::size_t>(grid.ni) * grid.nj;
  cover->fraction.assign(n, kNaN);
  std::size_t lo = levels.front().second->meta.field, hi = lo;
  for (const auto& [p, f] : levels) {
    lo = std::min(lo, f->meta.field);
    hi = std::max(hi, f->meta.field);
  }
  cover->source = "Sundqvist on r at " + std::to_string(levels.size()) + " " + band + " levels, fields " +
                  std::to_string(lo) + "-" + std::to_string(hi);
  auto heightOf = [&](double p, std::size_t k) {
    const auto it = s.height.find(p);
    if (it != s.height.end() && it->second->meta.grid == grid && std::isfinite(it->second->values[k]))
      return static_cast<double>(it->second->values[k]);
    return weather::isaAltitude_m(p / 100);
  };
  for (std::size_t k = 0; k < n; ++k) {
    float best = kNaN;
    double base = 0, top = 0;
    bool cloudy = false;
    for (const auto& [p, f] : levels) {
      const float rh = f->values[k];
      if (std::isnan(rh)) continue;
      const double u = std::clamp(rh / 100.0, 0.0, 1.0);
      const float c = u <= kCriticalHumidity ? 0.0f
                                             : static_cast<float>(1 - std::sqrt((1 - u) / (1 - kCriticalHumidity)));
      best = std::isnan(best) ? c : std::max(best, c);
      if (c > 0) {
        if (!cloudy) base = heightOf(p, k);
        top = heightOf(p, k);
        cloudy = true;
      }
    }
    cover->fraction[k] = best;
    if (cloudy && best > kCloudyCover) {
      d.bases_m.push_back(base);
      d.tops_m.push_back(top);
    }
  }
  d.cover = cover;
  return d;
}

}  // namespace

bool forecastWants(const GribMeta& m) {
  if (m.discipline != 0) return false;
  if (coverSlot(m)) return true;
  const bool isobaric = m.levelType == kIsobaric, nearGround = m.levelType == kHeightAboveGround;
  switch (m.category) {
    case kCatMass:
      return (m.number == kPressure || m.number == kGeopotentialHeight) &&
             (m.levelType == kCloudBase || m.levelType == kCloudTop || limitSlot(m.levelType) || isobaric);
    case kCatMoisture:
      return (m.number == kRelativeHumidity && (isobaric || nearGround)) ||
             ((m.number == kPrecipitationRate || (m.number >= kCategoricalRain && m.number <= kCategoricalSnow)) &&
              m.levelType == kSurface);
    case kCatMomentum: return (m.number == 2 || m.number == 3 || m.number == 8 || m.number == 9) && (isobaric || nearGround);
    case kCatTemperature: return m.number == 0 && (isobaric || nearGround);
    default: return false;
  }
}

Result<Forecast> Forecast::fromGrib(const std::vector<const GribFile*>& files, std::string name) {
  Forecast fc;
  fc.name_ = std::move(name);
  std::map<std::int64_t, StepFields> steps;
  std::optional<std::int64_t> reference;
  for (const GribFile* file : files)
    for (const GribField& f : file->fields) {
      StepFields& s = steps[f.meta.valid_unix];
      if (!reference || f.meta.reference_unix < *reference) reference = f.meta.reference_unix;
      const bool pa = f.meta.levelType == kIsobaric && std::isfinite(f.meta.level);
      if (auto slot = coverSlot(f.meta)) {
        if (!s.cover.emplace(*slot, &f).second) fc.notes_.push_back("ignored (a second cover of its layer): " + describe(f));
      } else if (f.meta.category == kCatMass && f.meta.number == kPressure) {
        if (auto lim = limitSlot(f.meta.levelType)) s.limit.emplace(*lim, &f);
        if (f.meta.levelType == kCloudBase) s.cloudBasePressure = &f;
      } else if (f.meta.category == kCatMass && f.meta.number == kGeopotentialHeight) {
        if (pa) s.height.emplace(f.meta.level, &f);
        if (f.meta.levelType == kCloudBase) s.cloudBaseHeight = &f;
      } else if (f.meta.category == kCatMoisture && f.meta.number == kRelativeHumidity && pa) {
        s.humidity.emplace(f.meta.level, &f);
      } else if (f.meta.category == kCatMoisture && f.meta.levelType == kSurface) {
        if (f.meta.number == kPrecipitationRate && !s.precipitationRate) s.precipitationRate = &f;
        if (f.meta.number >= kCategoricalRain && f.meta.number <= kCategoricalSnow) s.categorical.emplace(f.meta.number, &f);
      }
    }
  std::map<std::uint32_t, ForecastLayer> layers;
  // Heights per slot from the first step that gives any (bases, tops in m MSL).
  std::map<std::uint32_t, std::pair<double, double>> heights;
  std::map<std::uint32_t, std::string> heightFrom;
  bool baseFromCloudBase = false;
  std::map<weather::CloudType, std::size_t> precipitationVotes;
  for (auto& [valid, s] : steps) {
    std::map<std::uint32_t, std::shared_ptr<const CoverGrid>> covers;
    for (const auto& [slot, f] : s.cover) {
      auto g = std::make_shared<CoverGrid>();
      g->grid = f->meta.grid;
      g->source = describe(*f);
      const float scale = coverScale(*f);
      g->fraction.resize(f->values.size());
      for (std::size_t k = 0; k < f->values.size(); ++k)
        g->fraction[k] = std::isnan(f->values[k]) ? kNaN : std::clamp(f->values[k] * scale, 0.0f, 1.0f);
      // Layer limits from their pressures, over the points with cloud.
      std::vector<double> bottoms, tops;
      const GribField* bottom = s.limit.count({slot, true}) ? s.limit.at({slot, true}) : nullptr;
      const GribField* top = s.limit.count({slot, false}) ? s.limit.at({slot, false}) : nullptr;
      if (bottom && top && bottom->meta.grid == g->grid && top->meta.grid == g->grid && !heights.count(slot)) {
        for (std::size_t k = 0; k < g->fraction.size(); ++k) {
          const float pb = bottom->values[k], pt = top->values[k];
          if (g->fraction[k] > kCloudyCover && pb > 10000 && pb < 110000 && pt > 5000 && pt < pb) {
            bottoms.push_back(weather::isaAltitude_m(pb / 100));
            tops.push_back(weather::isaAltitude_m(pt / 100));
          }
        }
        if (!bottoms.empty()) {
          heights[slot] = {median(bottoms), median(tops)};
          heightFrom[slot] = "median of " + describe(*bottom) + " and " + describe(*top) + " (standard atmosphere)";
        }
      }
      covers[slot] = std::move(g);
    }
    const bool layered = covers.count(kForecastLowSlot) || covers.count(kForecastMiddleSlot) ||
                         covers.count(kForecastHighSlot);
    if (!layered && !s.humidity.empty()) {
      const std::pair<std::uint32_t, std::pair<double, double>> bands[] = {
          {kForecastLowSlot, {kLowTop_pa, 2e5}},
          {kForecastMiddleSlot, {kMiddleTop_pa, kLowTop_pa}},
          {kForecastHighSlot, {0, kMiddleTop_pa}}};
      for (const auto& [slot, band] : bands) {
        Derived d = deriveBand(s, band.first, band.second, slotDefaults(slot).name);
        if (!d.cover) continue;
        if (!heights.count(slot) && !d.bases_m.empty()) {
          heights[slot] = {median(d.bases_m), median(d.tops_m)};
          heightFrom[slot] = "median height of the humid levels (their geopotential)";
        }
        covers[slot] = std::move(d.cover);
      }
    }
    // A cloud-base height (NAM's) sets the lowest layer's base.
    if (s.cloudBaseHeight && covers.count(kForecastLowSlot) && !baseFromCloudBase) {
      std::vector<double> bases;
      for (float v : s.cloudBaseHeight->values)
        if (v >= 0 && v < 20000) bases.push_back(v);
      if (!bases.empty()) {
        auto& h = heights[kForecastLowSlot];
        const double top = h.second > 0 ? h.second : slotDefaults(kForecastLowSlot).base_m + slotDefaults(kForecastLowSlot).thickness_m;
        const double base = median(bases);
        if (base < top) {
          h = {base, top};
          heightFrom[kForecastLowSlot] = "base: median of " + describe(*s.cloudBaseHeight) + "; top: " +
                                         (heightFrom.count(kForecastLowSlot) ? heightFrom[kForecastLowSlot] : "typical");
          baseFromCloudBase = true;
        }
      }
    }
    if (s.precipitationRate) covers[kForecastPrecipitationSlot] = precipitationGrid(s, precipitationVotes);
    for (auto& [slot, g] : covers) {
      ForecastLayer& l = layers[slot];
      l.steps.push_back({valid, std::move(g)});
    }
  }
  if (layers.empty()) {
    std::string names;
    for (const GribFile* f : files) names += (names.empty() ? "" : ", ") + std::to_string(f->fields.size());
    return fail(ErrorCode::InvalidArgument, fc.name_ + ": no field gives cloud cover (cover per layer, or relative "
                                                       "humidity on pressure levels); fields read: " + names);
  }
  std::set<std::int64_t> valids;
  for (auto& [slot, l] : layers) {
    const SlotDefaults& d = slotDefaults(slot);
    l.layer.id = slot;
    l.layer.type = d.type;
    l.layer.coverage = 0;
    l.layer.density = 1;
    l.layer.base_m = d.base_m;
    l.layer.thickness_m = d.thickness_m;
    l.heightFrom = "typical " + std::string(d.name) + " cloud";
    if (auto h = heights.find(slot); h != heights.end() && std::isfinite(h->second.first)) {
      l.layer.base_m = std::clamp(h->second.first, 0.0, 19000.0);
      // A layer one level thick is still a layer: at least its typical depth's third.
      l.layer.thickness_m = std::clamp(h->second.second - l.layer.base_m, d.thickness_m / 3, 20000.0 - l.layer.base_m);
      l.heightFrom = heightFrom[slot];
    }
    if (slot == kForecastPrecipitationSlot) {
      // From the ground into the lowest cloud layer (the slots before it
      // are in fc.layers_ already), of the type most raining points have.
      double lowest = std::numeric_limits<double>::infinity();
      for (const ForecastLayer& other : fc.layers_) lowest = std::min(lowest, other.layer.base_m);
      l.layer.base_m = 0;
      if (std::isfinite(lowest)) {
        l.layer.thickness_m = std::clamp(lowest + kPrecipitationIntoCloud_m, 500.0, 20000.0);
        l.heightFrom = "from the ground to " + std::to_string(static_cast<int>(kPrecipitationIntoCloud_m)) +
                       " m into the lowest cloud layer";
      }
      std::size_t most = 0;
      for (const auto& [type, n] : precipitationVotes)
        if (n > most) {
          most = n;
          l.layer.type = type;
        }
    }
    l.layer.transitionBand_m = std::min(200.0, l.layer.thickness_m / 4);
    for (const auto& st : l.steps) valids.insert(st.valid_unix);
    fc.notes_.push_back(std::string(d.name) + " (layer " + std::to_string(slot) + ", " +
                        std::string(weather::toString(d.type)) + "): " + std::to_string(l.steps.size()) + " step(s) from " +
                        l.steps.front().cover->source + "; base " + std::to_string(static_cast<int>(l.layer.base_m)) +
                        " m, " + std::to_string(static_cast<int>(l.layer.thickness_m)) + " m thick: " + l.heightFrom);
    fc.layers_.push_back(std::move(l));
  }
  fc.wind_ = ForecastWind::fromGrib(files, fc.notes_);
  fc.air_ = ForecastAir::fromGrib(files, fc.notes_);
  fc.reference_unix_ = reference.value_or(0);
  fc.firstValid_unix_ = *valids.begin();
  fc.lastValid_unix_ = *valids.rbegin();
  fc.stepCount_ = valids.size();
  return fc;
}

float Forecast::coverage(const ForecastLayer& layer, double lat_deg, double lon_deg, double valid_unix) const {
  return atValidTime(
      layer.steps, valid_unix,
      [&](const ForecastLayer::Step& s) { return sampleField(s.cover->grid, s.cover->fraction, lat_deg, lon_deg); },
      [](float a, float b, double t) {
        if (std::isnan(a)) return b;
        if (std::isnan(b)) return a;
        return static_cast<float>(a + t * (b - a));
      });
}

weather::CoverageTile Forecast::tileAt(const ForecastLayer& layer, double lat_deg, double lon_deg,
                                       double valid_unix) const {
  weather::CoverageTile t{0, layer.layer.id, coverage(layer, lat_deg, lon_deg, valid_unix), 1.0f};
  if (layer.layer.id == kForecastPrecipitationSlot) {
    const float rate = t.coverage;  // the precipitation layer's grid holds its rate
    if (std::isnan(rate)) return t;
    t.coverage = rate >= kMinForecastPrecipitation_mmph ? 1.0f : 0.0f;
    t.density = static_cast<float>(weather::precipitationDensityForRate(layer.layer.type, rate));
    return t;
  }
  if (layer.layer.id == kForecastConvectiveSlot && t.coverage > kCbFrom) {
    t.blendType = weather::CloudType::Cumulonimbus;
    t.blend = std::clamp((t.coverage - kCbFrom) / (kCbFull - kCbFrom), 0.0f, 1.0f);
  }
  return t;
}

std::string Forecast::sourceAt(const ForecastLayer& layer, double lat_deg, double lon_deg, double valid_unix) const {
  const auto& steps = layer.steps;
  const ForecastLayer::Step* s = &steps.front();
  for (const auto& st : steps)
    if (std::abs(static_cast<double>(st.valid_unix) - valid_unix) < std::abs(static_cast<double>(s->valid_unix) - valid_unix))
      s = &st;
  const auto p = locate(s->cover->grid, lat_deg, lon_deg);
  if (!p) return "";
  const int i = std::clamp(static_cast<int>(std::lround(p->i)), 0, s->cover->grid.ni - 1);
  const int j = std::clamp(static_cast<int>(std::lround(p->j)) % s->cover->grid.nj, 0, s->cover->grid.nj - 1);
  const LatLon at = gridLatLon(s->cover->grid, i, j);
  char where[96];
  std::snprintf(where, sizeof where, "grid point (%d, %d) at %.2f, %.2f", i, j, at.lat_deg, at.lon_deg);
  return name_ + ": " + s->cover->source + ", " + where;
}

ForecastField::ForecastField(std::shared_ptr<const Forecast> forecast, std::uint64_t serial, double valid_unix)
    : forecast_(std::move(forecast)), valid_unix_(std::floor(valid_unix / kForecastTimeQuantum_s) * kForecastTimeQuantum_s) {
  // serial and quantum index mixed (FNV-1a over the two words).
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint64_t v : {serial, static_cast<std::uint64_t>(static_cast<std::int64_t>(valid_unix_ / kForecastTimeQuantum_s))}) {
    h ^= v;
    h *= 1099511628211ull;
  }
  key_ = h;
}

std::optional<weather::WindVector> Forecast::windAt(const ForecastLayer& layer, double lat_deg, double lon_deg,
                                                   double valid_unix) const {
  return wind_.at(lat_deg, lon_deg, layer.layer.base_m + layer.layer.thickness_m / 2, valid_unix);
}

bool ForecastField::givesWind(std::uint32_t layerId) const {
  return !forecast_->wind().empty() && gives(layerId);
}

void ForecastField::sampleWind(std::uint32_t layerId, std::span<const weather::CellCentre> at,
                               std::span<weather::WindVector> out) const {
  const ForecastLayer* layer = nullptr;
  for (const ForecastLayer& l : forecast_->layers())
    if (l.layer.id == layerId) layer = &l;
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < at.size() && k < out.size(); ++k) {
    const auto w = layer ? forecast_->windAt(*layer, at[k].lat_deg, at[k].lon_deg, valid_unix_) : std::nullopt;
    out[k] = w.value_or(weather::WindVector{kNone, kNone, kNone});
  }
}

std::vector<double> ForecastField::airLevels() const { return forecast_->air().levels_m(); }

void ForecastField::sampleAir(std::size_t level, std::span<const weather::CellCentre> at,
                              std::span<weather::AirValues> out) const {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < at.size() && k < out.size(); ++k)
    out[k] = forecast_->air().at(level, at[k].lat_deg, at[k].lon_deg, valid_unix_).value_or(weather::AirValues{kNone, kNone});
}

bool ForecastField::gives(std::uint32_t layerId) const {
  return std::any_of(forecast_->layers().begin(), forecast_->layers().end(),
                     [&](const ForecastLayer& l) { return l.layer.id == layerId; });
}

void ForecastField::sample(std::uint32_t layerId, std::span<const weather::CellCentre> at,
                           std::span<weather::CoverageTile> out) const {
  const ForecastLayer* layer = nullptr;
  for (const ForecastLayer& l : forecast_->layers())
    if (l.layer.id == layerId) layer = &l;
  for (std::size_t k = 0; k < at.size() && k < out.size(); ++k)
    out[k] = layer ? forecast_->tileAt(*layer, at[k].lat_deg, at[k].lon_deg, valid_unix_)
                   : weather::CoverageTile{0, layerId, kNaN, 1};
}

}  // namespace sky::server
