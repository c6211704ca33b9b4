// The cloud-type table and the weather map's type blend (renderer/core/src):
// every CIGI type has numbers inside the ranges the density model needs and
// its source states; the ice types are thin, icy and fibrous or cellular; a
// cumulonimbus has the anvil; the weather map picks one blend type per layer
// and carries the blend weight only for the tiles that name it; uniform
// layers are marked untiled.
#include <algorithm>

#include <gtest/gtest.h>

#include "cloud_types.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/tiling.hpp"
#include "weather_field.hpp"

namespace sky::render {
namespace {

using weather::CloudType;

constexpr CloudType kAll[] = {CloudType::Altocumulus,  CloudType::Altostratus,  CloudType::Cirrocumulus,
                              CloudType::Cirrostratus, CloudType::Cirrus,       CloudType::Cumulonimbus,
                              CloudType::Cumulus,      CloudType::Nimbostratus, CloudType::Stratocumulus,
                              CloudType::Stratus,      CloudType::Fog,          CloudType::Rain,
                              CloudType::Snow,         CloudType::Sleet,        CloudType::Hail};

bool isIce(CloudType t) {
  return t == CloudType::Cirrus || t == CloudType::Cirrostratus || t == CloudType::Cirrocumulus;
}

// Snow, ice pellets and hail: ice, but dense as precipitation.
bool isFrozenPrecipitation(CloudType t) {
  return t == CloudType::Snow || t == CloudType::Sleet || t == CloudType::Hail;
}

TEST(CloudTypes, EveryTypeIsInsideTheModelsRanges) {
  for (CloudType t : kAll) {
    SCOPED_TRACE(std::string(weather::toString(t)));
    const CloudTypeParams& p = cloudTypeParams(t);
    // formulas.md: water clouds 0.01-0.15 1/m, cirrus 1e-4-1e-3.
    if (weather::isPrecipitation(t)) {
      // The density is the extinction the answers and the radar assume.
      EXPECT_EQ(p.extinction_perm, weather::kPrecipitationExtinctionPerDensity_perm);
      EXPECT_EQ(p.dropletDiameter_um, isFrozenPrecipitation(t) ? 0.0 : 50.0)
          << "ice: HG phase; raindrops: the droplet fit's most forward end";
    } else if (isIce(t)) {
      EXPECT_GE(p.extinction_perm, 1e-4);
      EXPECT_LE(p.extinction_perm, 1e-3);
      EXPECT_EQ(p.dropletDiameter_um, 0.0) << "ice: HG phase, not the droplet fit";
    } else {
      EXPECT_GE(p.extinction_perm, 0.01);
      EXPECT_LE(p.extinction_perm, 0.15);
      EXPECT_GE(p.dropletDiameter_um, 5.0) << "Jendersie-d'Eon fit range";
      EXPECT_LE(p.dropletDiameter_um, 50.0);
    }
    // Divisors of the height functions and the soft threshold are positive.
    for (double v : {p.baseRound, p.densityBaseFade, p.densityTopFade, p.coverageEdge, p.wispyHeight, p.peak})
      EXPECT_GT(v, 0.0);
    EXPECT_LT(p.topRoundStart, 1.0);
    EXPECT_LE(p.peak, 1.0);
    for (double v : {p.peakVariation, p.anvil, p.densityGradient, p.fibrous, p.erosion, p.columnFill}) {
      EXPECT_GE(v, 0.0);
      EXPECT_LE(v, 1.0);
    }
    EXPECT_LT(p.erosion, 1.0) << "erodeShape divides by 1 - erosion";
    EXPECT_GT(p.shapePeriod_m, p.detailPeriod_m);
    EXPECT_GE(p.streak, 1.0);
    EXPECT_EQ(p.anvil, t == CloudType::Cumulonimbus ? 1.0 : 0.0);
  }
  // The look of the ice clouds: cirrus fibrous, cirrocumulus small cells.
  EXPECT_EQ(cloudTypeParams(CloudType::Cirrus).fibrous, 1.0);
  EXPECT_GT(cloudTypeParams(CloudType::Cirrus).streak, 1.0) << "filaments";
  EXPECT_LT(cloudTypeParams(CloudType::Cirrocumulus).shapePeriod_m, cloudTypeParams(CloudType::Altocumulus).shapePeriod_m);
  EXPECT_LT(cloudTypeParams(CloudType::Altocumulus).shapePeriod_m, cloudTypeParams(CloudType::Cumulus).shapePeriod_m);
  // No type given draws as cumulus.
  EXPECT_EQ(&cloudTypeParams(CloudType::None), &cloudTypeParams(CloudType::Cumulus));
}

TEST(CloudTypes, PackingKeepsTheCoresOrder) {
  const CloudTypeParams& p = cloudTypeParams(CloudType::Cumulonimbus);
  const gpu::SkyCloudType g = packCloudType(p);
  EXPECT_FLOAT_EQ(g.a.x, float(p.extinction_perm));
  EXPECT_FLOAT_EQ(g.a.y, float(p.dropletDiameter_um));
  EXPECT_FLOAT_EQ(g.b.z, float(p.anvil));
  EXPECT_FLOAT_EQ(g.c.w, float(p.fibrous));
  EXPECT_FLOAT_EQ(g.d.z, float(p.columnFill));
}

TEST(WeatherField, BlendTowardsTheTypeWithTheMostWeight) {
  constexpr int kLevel = 10;
  weather::WeatherSnapshot s;
  s.tileLevel = kLevel;
  weather::CloudLayer cu;
  cu.id = 1;
  cu.type = CloudType::Cumulus;
  cu.base_m = 1000;
  cu.thickness_m = 1000;
  weather::CloudLayer ci = cu;
  ci.id = 2;
  ci.type = CloudType::Cirrus;
  ci.base_m = 9000;
  ci.coverage = 0.4;
  s.layers = {cu, ci};
  const geo::Geodetic here{46.0, 7.0, 500.0};
  const auto cells = weather::coverCap({here.lat_deg, here.lon_deg, 60000.0}, kLevel, 4000);
  ASSERT_GT(cells.size(), 10u);
  // Most cells blend towards cumulonimbus by 0.6, a few towards stratus by 1.
  for (std::size_t i = 0; i < cells.size(); ++i) {
    weather::CoverageTile t{cells[i], 1, 0.5f, 1.0f};
    if (i % 5 == 0) {
      t.blendType = CloudType::Stratus;
      t.blend = 1.0f;
    } else {
      t.blendType = CloudType::Cumulonimbus;
      t.blend = 0.6f;
    }
    s.tiles.push_back(t);
  }
  const WeatherField f = buildWeatherField(&s, here);
  EXPECT_EQ(f.blendType[0], CloudType::Cumulonimbus);
  EXPECT_EQ(f.blendType[1], CloudType::None);
  EXPECT_TRUE(f.tiled[0]);
  EXPECT_FALSE(f.tiled[1]) << "the cirrus layer has no tiles: uniform";
  // Over the covered part of the map: coverage 0.5; blend 0.6 where a tile
  // names cumulonimbus and 0 where it names stratus (a slice holds one blend
  // type), never stratus' 1. Texel centres, so no value is interpolated.
  const double texel_m = 2 * f.halfExtent_m[0] / f.size;
  double lowest = 1, highest = 0;
  for (int j = -40; j < 40; ++j)
    for (int i = -40; i < 40; ++i) {
      const glm::dvec3 v = f.sample(0, (i + 0.5) * texel_m, (j + 0.5) * texel_m);
      EXPECT_NEAR(v.x, 0.5, 1.0 / 255);
      lowest = std::min(lowest, v.z);
      highest = std::max(highest, v.z);
    }
  EXPECT_NEAR(highest, 0.6, 1.0 / 255);
  EXPECT_EQ(lowest, 0.0);
  // The uniform cirrus layer: its own coverage everywhere on the map, no blend.
  EXPECT_NEAR(f.sample(1, 50000.0, -30000.0).x, 0.4, 1.0 / 255);
  EXPECT_EQ(f.sample(1, 50000.0, -30000.0).z, 0.0);
  // Blend changes the map's content key.
  weather::WeatherSnapshot other = s;
  other.tiles[1].blend = 0.7f;
  EXPECT_NE(weatherContentKey(&s), weatherContentKey(&other));
}

}  // namespace
}  // namespace sky::render
