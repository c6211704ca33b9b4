// Precipitation near the camera (renderer/core/src/near_precip.cpp and
// shaders/include/precip_streak.glsl compiled as C++): a streak spreads its
// drop's area and no more; the drops are as many and as large as the
// published laws give; their streaks move as the wind, their fall and the
// camera's motion make them; a frame's end is the next frame's start; the
// tile lists hold every streak a pixel sees.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "near_precip.hpp"
#include "precip_streak.hpp"
#include "sky/weather/precipitation.hpp"

namespace sky::test {
namespace {

using Streak = render::PrecipStreak;

constexpr double kPi = 3.14159265358979323846;
using weather::CloudType;

// The coverage summed over the pixel centres of a grid round the streak.
double summedCoverage(glm::dvec2 a, glm::dvec2 b, double r) {
  const glm::dvec2 lo = glm::floor(glm::min(a, b) - r - 2.0), hi = glm::ceil(glm::max(a, b) + r + 2.0);
  double sum = 0;
  for (double y = lo.y; y <= hi.y; ++y)
    for (double x = lo.x; x <= hi.x; ++x) sum += Streak{}.streakCoverage(glm::dvec2(x + 0.5, y + 0.5), a, b, r);
  return sum;
}

TEST(StreakCoverage, ADropsLightIsSpreadNotMadeAtAnyLengthAndAngle) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(0.0, 1.0);
  for (double r : {0.15, 0.5, 1.7, 4.0})
    for (double len : {0.0, 2.5, 40.0, 300.0})
      for (double angle_deg : {0.0, 17.0, 45.0, 90.0}) {
        SCOPED_TRACE("r " + std::to_string(r) + " px, length " + std::to_string(len) + " px, angle " +
                     std::to_string(angle_deg));
        const double t = angle_deg * kPi / 180;
        const glm::dvec2 dir(std::cos(t), std::sin(t));
        const double area = kPi * r * r;
        // Where the drop's image would pass 1 (wide and nearly still), it
        // is cut to 1 and gives less than its area.
        const bool cut = area / (std::max(r, 1.0) * std::max({r, 1.0, len})) > 1;
        double mean = 0, worst = 0;
        constexpr int kPlaces = 32;
        for (int k = 0; k < kPlaces; ++k) {
          const glm::dvec2 a(50 + offset(rng), 50 + offset(rng));
          const double sum = summedCoverage(a, a + len * dir, r);
          if (cut) {
            EXPECT_LE(sum, area);
            EXPECT_GT(sum, 0.5 * area);
          }
          mean += sum / kPlaces;
          worst = std::max(worst, std::abs(sum / area - 1));
        }
        if (cut) continue;
        // The tents' sums over pixel centres ripple with the drop's place
        // on the pixel grid (exactly flat only for a tent a whole number of
        // pixels wide along an axis): a streak's brightness varies by that
        // much as it crosses the pixels.
        EXPECT_LT(worst, 0.12);
        EXPECT_NEAR(mean, area, 0.03 * area);
        if (r <= 1 && (angle_deg == 0.0 || angle_deg == 90.0)) {
          EXPECT_LT(worst, 1e-9);
        }
      }
}

TEST(StreakCoverage, IsTheShareOfTheExposureTheDropCoversAPixel) {
  // A drop of radius 2 px moving 40 px right along a row of pixel centres:
  // in the middle of its path a pixel on it gets the drop's area over the
  // path's length times the tent's peak across (1 / 2).
  const glm::dvec2 a(0.5, 0.5), b(40.5, 0.5);
  EXPECT_NEAR(Streak{}.streakCoverage(glm::dvec2(20.5, 0.5), a, b, 2.0), kPi * 4 / 40 / 2, 1e-12);
  // A pixel off the path by 1 px, half that.
  EXPECT_NEAR(Streak{}.streakCoverage(glm::dvec2(20.5, 1.5), a, b, 2.0), kPi * 4 / 40 / 4, 1e-12);
  // Past the ends and beside the path, nothing.
  EXPECT_EQ(Streak{}.streakCoverage(glm::dvec2(43.0, 0.5), a, b, 2.0), 0.0);
  EXPECT_EQ(Streak{}.streakCoverage(glm::dvec2(20.5, 3.0), a, b, 2.0), 0.0);
  // Twice as long a path, half as bright.
  EXPECT_NEAR(Streak{}.streakCoverage(glm::dvec2(20.5, 0.5), a, glm::dvec2(80.5, 0.5), 2.0),
              0.5 * Streak{}.streakCoverage(glm::dvec2(20.5, 0.5), a, b, 2.0), 1e-12);
}

// The number of drops at least dMin across per m^3, by summing the law's
// N0 e^(-Lambda D) in steps of 1 um.
double integratedCount(double n0, double lambda, double dMin) {
  double sum = 0;
  for (double d = dMin; d < dMin + 40 / lambda; d += 1e-3) sum += n0 * std::exp(-lambda * (d + 0.5e-3)) * 1e-3;
  return sum;
}

TEST(DropPopulation, RainAndSnowAreAsManyAsTheirLawsGive) {
  for (double rate : {1.0, 8.0}) {
    const render::DropPopulation p = render::dropPopulation(CloudType::Rain, rate);
    const double lambda = 4.1 * std::pow(rate, -0.21);
    EXPECT_NEAR(p.lambda_permm, lambda, 1e-12);
    EXPECT_NEAR(p.numberDensity_perm3, integratedCount(8000, lambda, 1.0), 1e-3 * p.numberDensity_perm3);
    EXPECT_EQ(p.count, std::uint32_t(std::lround(p.numberDensity_perm3 * std::pow(p.box_m, 3))));
    EXPECT_FALSE(p.capped);
    EXPECT_DOUBLE_EQ(p.radianceFactor, 0.94);
  }
  // 8 mm/h: 213 drops of 1 mm or more in each cubic metre.
  EXPECT_NEAR(render::dropPopulation(CloudType::Rain, 8).numberDensity_perm3, 213.5, 0.1);
  const double snowRate = 0.5;
  const render::DropPopulation snow = render::dropPopulation(CloudType::Snow, snowRate);
  EXPECT_NEAR(snow.numberDensity_perm3,
              integratedCount(3800 * std::pow(snowRate, -0.87), 2.55 * std::pow(snowRate, -0.48), 1.0),
              1e-3 * snow.numberDensity_perm3);
  EXPECT_GT(snow.box_m, render::dropPopulation(CloudType::Rain, 1).box_m) << "flakes are seen farther";
  // A downpour asks for more than are drawn, and says so.
  const render::DropPopulation heavy = render::dropPopulation(CloudType::Rain, 100);
  EXPECT_TRUE(heavy.capped);
  EXPECT_EQ(heavy.count, render::kMaxNearDrops);
  // No precipitation, no drops.
  EXPECT_EQ(render::dropPopulation(CloudType::Cumulus, 5).count, 0u);
  EXPECT_EQ(render::dropPopulation(CloudType::Rain, 0).count, 0u);
  EXPECT_EQ(render::dropPopulation(CloudType::Rain, std::nan("")).count, 0u);
}

TEST(DropPopulation, RaindropsFallAtAtlasSpeeds) {
  // Atlas et al. 1973 at 1, 2 and 5 mm, and the large-drop limit.
  EXPECT_NEAR(render::raindropFallSpeed_mps(1), 9.65 - 10.3 * std::exp(-0.6), 1e-12);
  EXPECT_NEAR(render::raindropFallSpeed_mps(2), 6.55, 0.01);
  EXPECT_NEAR(render::raindropFallSpeed_mps(5), 9.14, 0.01);
  EXPECT_EQ(render::raindropFallSpeed_mps(0.01), 0.0);
}

// A camera at 300 m at 46 N 13 E looking north, level; 640 x 360, 60 degrees
// up and down... of vertical field of view.
render::NearPrecipInputs camera(CloudType type, double rate) {
  render::NearPrecipInputs in;
  in.type = type;
  in.rate_mmph = rate;
  in.clock_s = 1000;
  in.exposure_s = 1.0 / 30;
  const double lat = 46 * kPi / 180, lon = 13 * kPi / 180;
  const glm::dvec3 east(-std::sin(lon), std::cos(lon), 0);
  const glm::dvec3 north(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat));
  const glm::dvec3 up(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
  in.localToEcef = glm::dmat3(east, north, up);
  in.cameraEcef_m = 6.3785e6 * up;
  in.camForward = {0, 1, 0};
  in.camRight = {1, 0, 0};
  in.camDown = {0, 0, -1};
  const double t = std::tan(30 * kPi / 180);
  in.frustum = {-t * 16 / 9, t * 16 / 9, t, -t};
  in.width = 640;
  in.height = 360;
  in.seed = 3;
  return in;
}

glm::dvec2 ends0(const gpu::SkyStreak& s) { return {s.path.x, s.path.y}; }
glm::dvec2 ends1(const gpu::SkyStreak& s) {
  return ends0(s) + double(s.shape.x) * glm::dvec2(s.path.z, s.path.w);
}
double radius(const gpu::SkyStreak& s) { return s.shape.y; }
double depth(const gpu::SkyStreak& s) { return s.shape.z; }

TEST(NearPrecip, DropsAreAsLargeAsTheLawGives) {
  const render::NearPrecipInputs in = camera(CloudType::Rain, 8);
  const render::NearPrecipFrame f = render::buildNearPrecip(in);
  ASSERT_GT(f.streaks.size(), 500u);
  // Each streak's diameter back from its radius and distance.
  const double pixelsPerTangent = in.width / (in.frustum.y - in.frustum.x);
  double mean = 0;
  for (const auto& s : f.streaks) mean += 2e3 * radius(s) * depth(s) / pixelsPerTangent / double(f.streaks.size());
  // An exponential law cut at 1 mm: the mean is 1 mm + 1 / Lambda.
  EXPECT_NEAR(mean, 1.0 + 1.0 / f.population.lambda_permm, 0.03 * mean);
  double area = 0;
  for (const auto& s : f.streaks) area += kPi * radius(s) * radius(s);
  EXPECT_NEAR(f.dropArea_px2, area, 1e-6 * area);
  std::printf("[ near     ] rain 8 mm/h: %u drops in the %.0f m cube, %zu streaks on a 640x360 image, %.0f px^2\n",
              f.population.count, f.population.box_m, f.streaks.size(), f.dropArea_px2);
}

TEST(NearPrecip, AStillCameraSeesRainFallStraightDownAndTheWindLeanIt) {
  render::NearPrecipInputs in = camera(CloudType::Rain, 8);
  const render::NearPrecipFrame still = render::buildNearPrecip(in);
  ASSERT_GT(still.streaks.size(), 100u);
  for (const auto& s : still.streaks) {
    const glm::dvec2 d = ends1(s) - ends0(s);
    EXPECT_GT(d.y, 0) << "falls down the image";
    EXPECT_NEAR(d.x, 0, 1e-3 * std::abs(d.y) + 1e-3) << "a level camera sees a vertical fall as vertical";
  }
  // A west wind of 8 m/s: every drop drifts east, to the right of a camera
  // looking north, by 8 m/s against its fall of 4-9 m/s.
  in.airEnu_mps = {8, 0, 0};
  const render::NearPrecipFrame windy = render::buildNearPrecip(in);
  ASSERT_GT(windy.streaks.size(), 100u);
  for (const auto& s : windy.streaks) {
    const glm::dvec2 d = ends1(s) - ends0(s);
    EXPECT_GT(d.x, 0);
    EXPECT_GT(d.y, 0);
  }
}

TEST(NearPrecip, AMovingCameraSeesStreaksRunFromWhereItIsGoing) {
  render::NearPrecipInputs in = camera(CloudType::Rain, 8);
  in.cameraEnu_mps = {0, 60, 0};
  const render::NearPrecipFrame f = render::buildNearPrecip(in);
  ASSERT_GT(f.streaks.size(), 100u);
  // Each drop moves relative to the camera along one line; the image of a
  // line traced that way runs through the focus of expansion, the image of
  // the direction the camera moves through the drops' frame. That differs
  // per drop (its fall speed): the focus is straight ahead and above by
  // fall / 60.
  double longest = 0;
  for (const auto& s : f.streaks) {
    const double d_mm = 2e3 * radius(s) * depth(s) / (in.width / (in.frustum.y - in.frustum.x));
    const double fall = render::raindropFallSpeed_mps(d_mm);
    const glm::dvec2 focus(320.0, 180.0 - fall / 60.0 * 360.0 / (2 * in.frustum.z));
    const glm::dvec2 along = ends1(s) - ends0(s), out = ends0(s) - focus;
    const double len = glm::length(along);
    longest = std::max(longest, len);
    if (len < 1.0 || glm::length(out) < 5.0) continue;
    const double cross = (along.x * out.y - along.y * out.x) / (len * glm::length(out));
    EXPECT_NEAR(cross, 0, 0.02) << "the streak runs through the focus of expansion";
    EXPECT_GT(glm::dot(along, out), 0) << "away from it";
  }
  EXPECT_GT(longest, 100) << "a drop 1 m away passes the camera at 60 m/s in a long streak";
}

TEST(NearPrecip, AFramesEndIsTheNextFramesStart) {
  // Two frames an exposure apart with the camera moving and a wind: where
  // each drop ends in the first is where it starts in the second. A short
  // exposure (1/240 s), so that few drops leave the cube between the two
  // and come back at its far side.
  render::NearPrecipInputs in = camera(CloudType::Rain, 4);
  in.airEnu_mps = {3, -2, 0};
  in.cameraEnu_mps = {5, 20, 1};
  in.exposure_s = 1.0 / 240;
  const render::NearPrecipFrame first = render::buildNearPrecip(in);
  in.clock_s += in.exposure_s;
  in.cameraEcef_m += in.localToEcef * (in.cameraEnu_mps * in.exposure_s);
  const render::NearPrecipFrame second = render::buildNearPrecip(in);
  ASSERT_GT(first.streaks.size(), 100u);
  std::size_t matched = 0, inside = 0;
  for (const auto& s : second.streaks) {
    const glm::dvec2 start = ends0(s);
    // Drops that entered the cube through a face (1.5 m away at least)
    // since the first frame, and those out of the picture in it, have no
    // match.
    if (start.x < 1 || start.y < 1 || start.x > 639 || start.y > 359 || depth(s) > 1.3) continue;
    ++inside;
    double best = 1e9;
    for (const auto& t : first.streaks) best = std::min(best, glm::length(ends1(t) - start));
    matched += best < 1e-2 ? 1 : 0;
  }
  ASSERT_GT(inside, 100u);
  EXPECT_GT(double(matched), 0.98 * double(inside)) << matched << " of " << inside;
}

TEST(NearPrecip, AShorterExposureDrawsShorterStreaks) {
  // The same drops end where they are at the frame's clock; over 1/240 s
  // they travel an eighth of their 1/30 s path. A still camera looking level
  // and no wind: the drops fall at a constant distance from the image
  // plane, so their paths on the image scale exactly.
  render::NearPrecipInputs in = camera(CloudType::Rain, 8);
  const render::NearPrecipFrame slow = render::buildNearPrecip(in);
  in.exposure_s = 1.0 / 240;
  const render::NearPrecipFrame fast = render::buildNearPrecip(in);
  std::size_t compared = 0;
  for (const auto& s : fast.streaks) {
    for (const auto& t : slow.streaks) {
      if (glm::length(ends1(s) - ends1(t)) > 1e-3) continue;
      EXPECT_NEAR(glm::length(ends1(s) - ends0(s)), glm::length(ends1(t) - ends0(t)) / 8,
                  1e-4 * glm::length(ends1(t) - ends0(t)) + 1e-3);
      ++compared;
    }
  }
  EXPECT_GT(compared, 50u);
}

TEST(NearPrecip, SameInputsSameDropsAndMoreRainAddsDrops) {
  const render::NearPrecipInputs in = camera(CloudType::Snow, 1.5);
  const render::NearPrecipFrame a = render::buildNearPrecip(in), b = render::buildNearPrecip(in);
  ASSERT_EQ(a.streaks.size(), b.streaks.size());
  for (std::size_t i = 0; i < a.streaks.size(); ++i) EXPECT_EQ(a.streaks[i].path, b.streaks[i].path);
  EXPECT_EQ(a.entries, b.entries);
  EXPECT_LT(render::buildNearPrecip(camera(CloudType::Rain, 2)).streaks.size(),
            render::buildNearPrecip(camera(CloudType::Rain, 8)).streaks.size());
  // No drops within kNearestDrop_m.
  for (const auto& s : a.streaks) EXPECT_GE(depth(s), render::kNearestDrop_m - 1e-6);
}

TEST(NearPrecip, EachPixelsTileListsEveryStreakThatCoversIt) {
  render::NearPrecipInputs in = camera(CloudType::Rain, 8);
  in.cameraEnu_mps = {10, 40, 0};
  const render::NearPrecipFrame f = render::buildNearPrecip(in);
  ASSERT_GT(f.streaks.size(), 100u);
  std::mt19937 rng(9);
  std::size_t covered = 0;
  for (int k = 0; k < 4000; ++k) {
    const glm::dvec2 p(double(rng() % in.width) + 0.5, double(rng() % in.height) + 0.5);
    double all = 1, listed = 1;
    for (const auto& s : f.streaks) all *= 1 - Streak{}.streakCoverage(p, ends0(s), ends1(s), radius(s));
    const glm::uvec2 range = f.tiles[std::size_t(p.y / gpu::kNearPrecipTile) * f.tilesX +
                                     std::size_t(p.x / gpu::kNearPrecipTile)];
    for (std::uint32_t e = range.x; e < range.x + range.y; ++e) {
      const auto& s = f.streaks[f.entries[e]];
      listed *= 1 - Streak{}.streakCoverage(p, ends0(s), ends1(s), radius(s));
    }
    EXPECT_NEAR(listed, all, 1e-12);
    covered += all < 1 ? 1 : 0;
  }
  EXPECT_GT(covered, 50u) << "the check saw streaks";
}

TEST(NearPrecip, ACameraVelocityIsOnlyTakenFromAPlausibleStep) {
  const glm::dvec3 p(6.4e6, 0, 0);
  EXPECT_EQ(render::cameraVelocityEcef(p, 10, p + glm::dvec3(0, 10, 0), 10.5), glm::dvec3(0, 20, 0));
  EXPECT_FALSE(render::cameraVelocityEcef(p, 10, p, 10));        // a paused clock
  EXPECT_FALSE(render::cameraVelocityEcef(p, 10, p, 9));         // backwards
  EXPECT_FALSE(render::cameraVelocityEcef(p, 10, p, 12));        // a gap
  EXPECT_FALSE(render::cameraVelocityEcef(p, 10, p + glm::dvec3(0, 600, 0), 10.5));  // a jump
}

}  // namespace
}  // namespace sky::test
