// The cloud-type table (see cloud_types.hpp). Sources, by column:
//  * extinction: formulas.md's magnitudes (sigma_t ~ 3 LWC / (2 rho_w r_e)):
//    cumulus 0.05-0.15 1/m, stratus 0.01-0.05, cirrus (ice) 1e-4-1e-3; within
//    those ranges, deeper and wetter types higher. The low ends also keep a
//    48-step march over a layer from aliasing.
//  * droplet diameter: effective radii ~5-10 um in non-precipitating water
//    clouds and larger in precipitating ones (e.g. Miles, Verlinde & Clothiaux
//    2000, "Cloud droplet size distributions in low-level stratiform clouds"),
//    so 2 r_e = 10-14 um, 20 um for nimbostratus and cumulonimbus; 0 marks ice.
//  * height profile and density profile: Haggstrom 2018 eq. 5-10 (cumulus:
//    0.07, 0.2, 0.15, 0.1, density growing with height), anvils eq. 17-18; the
//    sheet types' flat tops and uniform density follow his sec. 5.1.1 (stratus
//    = a thinner height channel and lower density, stratocumulus = larger,
//    less dense cells) and the descriptions in his sec. 2.1.2.
//  * erosion: Haggstrom eq. 14 (0.35, wispy to billowy at ph = 0.2); less for
//    the smooth sheets, more for the wispy ice clouds.
//  * column fill: the mean density over a column through a cloud (the
//    profiles' mean, about 0.5 for the growing cumulus profile, more for the
//    sheets, less for the wispy ice), for the depth the diffuse light crosses.
//  * streak: cirrus "in the form of filaments, strands or hooks" (Haggstrom
//    sec. 2.1.2.3): shape features 4x longer than wide, cirrostratus 2x.
//  * noise periods: cumulus' 5 km shape period puts ~1.2 km cells (4 Worley
//    cells per period), fair-weather cumulus size; the others scale that by
//    their cell size (stratocumulus ~2 km, altocumulus ~0.6 km, cirrocumulus
//    ~0.3 km "small grainy clouds", cumulonimbus ~4 km cells); the detail
//    period is a few times finer than the cells.
//  * fog (ours, CIGI leaves type 11 to the IG): a sheet that fills its layer
//    uniformly (a soft threshold far below the noise's range, flat base, no
//    density gradient), so a horizontal sight line through it sees the
//    extinction its density stands for (weather::kCloudExtinctionPerDensity_perm,
//    the same number the CIGI answer turns into a visibility); it thins over
//    its top third, where real fog tops are ragged. Fog droplets 10-20 um
//    (2 r_e ~ 12 um in radiation fog).
//  * rain, snow, sleet, hail (ours, 12-15): shafts that fill their layer
//    (from the ground or the virga height up into the cloud that drops them)
//    like fog, their density being their extinction
//    (weather::kPrecipitationExtinctionPerDensity_perm, from which the rate,
//    the answers' visibility and the radar's reflectivity follow:
//    precipitation.hpp); flat at the bottom, thinning over the top third
//    where they enter their cloud; the shape noise at a storm cell's scale
//    breaks a partial coverage into shafts. Raindrops (0.5-3 mm) are far
//    past the Mie fit's 50 um, so rain takes its most forward-peaked end;
//    snow, ice pellets and hail scatter as ice.
// These are look-development numbers inside those bounds, not measurements.
#include "cloud_types.hpp"

#include <array>

#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::render {

namespace {

using weather::CloudType;

//                 ext     d_um  bRnd  tRnd  peak  pVar  anvl  grad  dBas  dTop  edge  fibr  eros  wisp  fill  shape_m  detail_m  streak
constexpr CloudTypeParams kCumulus{
    0.06,   14.0, 0.07, 0.20, 1.00, 0.50, 0.0,  1.00, 0.15, 0.10, 0.25, 0.0,  0.35, 0.20, 0.50, 5000.0,  1000.0};
constexpr CloudTypeParams kStratocumulus{
    0.04,   10.0, 0.10, 0.40, 1.00, 0.30, 0.0,  0.50, 0.15, 0.10, 0.30, 0.0,  0.30, 0.20, 0.60, 8000.0,  1500.0};
constexpr CloudTypeParams kStratus{
    0.03,   10.0, 0.10, 0.70, 1.00, 0.10, 0.0,  0.20, 0.20, 0.15, 0.50, 0.0,  0.20, 0.30, 0.80, 14000.0, 2000.0};
constexpr CloudTypeParams kNimbostratus{
    0.05,   20.0, 0.05, 0.70, 1.00, 0.15, 0.0,  0.30, 0.10, 0.15, 0.50, 0.0,  0.15, 0.20, 0.80, 14000.0, 2000.0};
constexpr CloudTypeParams kCumulonimbus{
    0.08,   20.0, 0.07, 0.20, 1.00, 0.20, 1.0,  1.00, 0.15, 0.10, 0.20, 0.0,  0.35, 0.20, 0.50, 16000.0, 2000.0};
constexpr CloudTypeParams kAltocumulus{
    0.03,   10.0, 0.10, 0.30, 1.00, 0.40, 0.0,  0.70, 0.15, 0.10, 0.25, 0.0,  0.35, 0.20, 0.50, 2500.0,  600.0};
constexpr CloudTypeParams kAltostratus{
    0.02,   10.0, 0.15, 0.70, 1.00, 0.10, 0.0,  0.20, 0.20, 0.20, 0.50, 0.0,  0.20, 0.30, 0.80, 14000.0, 2000.0};
constexpr CloudTypeParams kCirrus{
    5.0e-4, 0.0,  0.20, 0.30, 1.00, 0.50, 0.0,  0.30, 0.30, 0.30, 0.40, 1.0,  0.50, 0.50, 0.30, 10000.0, 1500.0, 4.0};
constexpr CloudTypeParams kCirrostratus{
    3.0e-4, 0.0,  0.30, 0.60, 1.00, 0.20, 0.0,  0.20, 0.30, 0.30, 0.60, 0.5,  0.30, 0.50, 0.60, 16000.0, 2000.0, 2.0};
constexpr CloudTypeParams kCirrocumulus{
    1.0e-3, 0.0,  0.20, 0.40, 1.00, 0.30, 0.0,  0.50, 0.30, 0.30, 0.25, 0.0,  0.40, 0.30, 0.40, 1200.0,  400.0};
constexpr CloudTypeParams kFog{
    weather::kCloudExtinctionPerDensity_perm,
            12.0, 0.01, 0.70, 1.00, 0.20, 0.0,  0.00, 0.01, 0.30, 0.05, 0.0,  0.10, 0.30, 0.85, 14000.0, 2000.0};
constexpr CloudTypeParams kRain{
    weather::kPrecipitationExtinctionPerDensity_perm,
            50.0, 0.01, 0.70, 1.00, 0.10, 0.0,  0.00, 0.01, 0.30, 0.05, 0.0,  0.10, 0.30, 0.85, 8000.0,  1500.0};
constexpr CloudTypeParams kSnow{
    weather::kPrecipitationExtinctionPerDensity_perm,
            0.0,  0.01, 0.70, 1.00, 0.10, 0.0,  0.00, 0.01, 0.30, 0.05, 0.0,  0.10, 0.30, 0.85, 8000.0,  1500.0};

// Indexed by the CIGI enum value (model.hpp).
constexpr std::array<const CloudTypeParams*, weather::kMaxCloudType + 1> kTable = {
    &kCumulus,       // None
    &kAltocumulus,   // 1
    &kAltostratus,   // 2
    &kCirrocumulus,  // 3
    &kCirrostratus,  // 4
    &kCirrus,        // 5
    &kCumulonimbus,  // 6
    &kCumulus,       // 7
    &kNimbostratus,  // 8
    &kStratocumulus, // 9
    &kStratus,       // 10
    &kFog,           // 11 (ours)
    &kRain,          // 12 (ours)
    &kSnow,          // 13 (ours)
    &kSnow,          // 14 sleet (ours): ice pellets
    &kSnow,          // 15 hail (ours): ice
};

static_assert(static_cast<int>(CloudType::Hail) == weather::kMaxCloudType);

}  // namespace

const CloudTypeParams& cloudTypeParams(weather::CloudType type) {
  const auto i = static_cast<std::size_t>(type);
  return i < kTable.size() ? *kTable[i] : kCumulus;
}

gpu::SkyCloudType packCloudType(const CloudTypeParams& p) {
  gpu::SkyCloudType t{};
  t.a = gpu::vec4(float(p.extinction_perm), float(p.dropletDiameter_um), float(p.baseRound), float(p.topRoundStart));
  t.b = gpu::vec4(float(p.peak), float(p.peakVariation), float(p.anvil), float(p.densityGradient));
  t.c = gpu::vec4(float(p.densityBaseFade), float(p.densityTopFade), float(p.coverageEdge), float(p.fibrous));
  t.d = gpu::vec4(float(p.erosion), float(p.wispyHeight), float(p.columnFill), 0.0f);
  return t;
}

}  // namespace sky::render
