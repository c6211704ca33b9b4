// A camera's exposure of the renderer's linear radiance: the renderer's units
// in physical ones, EV100 from a reflected-light meter's reading of a scene's
// mean log luminance, the exposure an EV100 gives (Lagarde & de Rousiers
// 2014), and the temporal adaptation of an auto exposure. Pure math; the
// metering of a frame's view is auto_exposure.hpp, the display transform that
// applies the exposure is writePng / tonemapToSrgb8.
#pragma once

#include <cstddef>

#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

// The sun's irradiance at the top of the atmosphere in the renderer's linear
// units, per channel (white: the atmosphere colours it). Chosen when the PNG
// had a fixed exposure of 1: it puts a clear noon zenith near 0.3-0.5 and a
// sunlit cloud top near 1-2, the tones ACES maps to mid and upper grey.
inline constexpr double kSunIrradiance_units = 20.0;
// Total solar irradiance at 1 AU, W/m^2 (Kopp & Lean 2011, GRL 38, L01706:
// 1360.8 +- 0.5 W/m^2 at solar minimum).
inline constexpr double kSolarConstant_Wpm2 = 1361.0;
// Solar illuminance at the top of the atmosphere, lx: the solar illuminance
// constant E_sc = 128 klx (Wikipedia "Sunlight", after the solar constant and
// a luminous efficacy of ~94 lm/W of the extraterrestrial spectrum; Darula,
// Kittler & Gueymard 2005, Lighting Res. Technol. 37(3), give 133.8 klx:
// 0.06 EV brighter, within what a meter's calibration spreads).
inline constexpr double kSolarIlluminance_lx = 128000.0;
// One unit of the renderer's radiance, per channel, in W m^-2 sr^-1 (68.05):
// the sun's kSunIrradiance_units stand for the solar constant.
inline constexpr double kRadianceUnit_Wpm2sr = kSolarConstant_Wpm2 / kSunIrradiance_units;
// One unit of the renderer's luminance (Rec. 709 Y of its rgb) in cd/m^2
// (6400): the sun's kSunIrradiance_units of Y stand for kSolarIlluminance_lx.
inline constexpr double kLuminanceUnit_cdm2 = kSolarIlluminance_lx / kSunIrradiance_units;

// The display transform's exposure before today's camera: radiance units x 1
// into the tonemap. skyshell-bench keeps it (its errors stay comparable), and
// callers that pass no exposure get it. It is the exposure of EV100
// log2(kLuminanceUnit_cdm2 / 1.2) = 12.38 (kFixedDisplayEv100).
inline constexpr double kFixedDisplayExposure = 1.0;
extern const double kFixedDisplayEv100;

// Reflected-light meter calibration constant K, cd s m^-2 ISO (ISO 2720:1974;
// 12.5 is Canon's, Nikon's and Sekonic's value): a meter reading the mean
// luminance L at ISO 100 gives EV100 = log2(L * 100 / K).
inline constexpr double kMeterCalibrationK = 12.5;
// Luminance added to every pixel before its logarithm, cd/m^2: keeps a black
// pixel (a non-finite one, a moonless night's ground) from driving the log
// mean to -inf. 1e-4 cd/m^2 is below a starlit sky's ~3e-4 (Rea 2000, IESNA
// Lighting Handbook, tab. 3-1), so it changes no scene the eye can see in.
inline constexpr double kMeterFloor_cdm2 = 1e-4;

// The auto exposure's range, EV100. Below 5 cd/m^2 the eye leaves the
// photopic range (CIE 191:2010 puts the mesopic between 0.005 and 5 cd/m^2)
// and no longer adapts to keep a scene mid-grey: dusk and night are seen
// darker, so the meter stops at EV100 log2(5 x 8) = 5.32 and night stays
// dark. 18 is past any daylit scene (sunlit snow is ~16).
inline constexpr double kMinAutoEv100 = 5.32;
inline constexpr double kMaxAutoEv100 = 18.0;

// Time constant of the auto exposure's adaptation, s: the EV100 moves to
// a new metered value as 1 - exp(-t / tau). The eye's fast adaptation of the
// cones has tau ~0.1 s and of the rods ~0.4 s (Krawczyk, Myszkowski & Seidel
// 2005, "Perceptual effects in real-time tone mapping", SCCG; after
// Pattanaik et al. 2000); a camera's auto exposure settles in about a second.
// 0.5 s: a cloud sliding past the sun or a turn towards it is followed
// within a second, without the frame-to-frame pumping a faster one shows
// when the metered view crosses a cloud's edge.
inline constexpr double kDefaultAdaptationTau_s = 0.5;

// EV100 a reflected-light meter at ISO 100 reads for a scene of this mean
// log luminance: meanLnLuminance is the mean of ln(L / (1 cd/m^2)) over the
// scene; EV100 = log2(exp(meanLn) * 100 / kMeterCalibrationK).
double ev100FromMeanLogLuminance(double meanLnLuminance);

// The exposure of an EV100, per cd/m^2 (Lagarde & de Rousiers 2014, "Moving
// Frostbite to PBR", "physically based camera": saturation-based speed, S = 100,
// q = 0.65): the luminance that saturates the sensor is L_max = 78 / (S q)
// 2^EV100 = 1.2 x 2^EV100, and exposure = 1 / L_max. A luminance L (cd/m^2)
// displays as L x exposure (1: white before the tonemap).
double exposureFromEv100(double ev100);

// The multiplier of the renderer's radiance units into the display transform
// (tonemapToSrgb8, writePng) for this EV100 and a compensation in EV
// (positive: brighter, as a camera's +1 EV doubles the exposure).
double displayExposure(double ev100, double compensation_ev);

// A scene's mean of ln(L / (1 cd/m^2)) over its finite pixels, L the Rec. 709
// luminance of the rgb in the renderer's units times kLuminanceUnit_cdm2,
// plus kMeterFloor_cdm2. An image without a finite pixel reads the floor's.
double meanLogLuminance(const Image& image);

// The adaptation of an auto exposure over time: each update moves the EV100
// towards the metered target by 1 - exp(-dt / tau). The first update, a time
// that went back, or a gap over kSnapAfterTaus time constants takes the
// target at once (a new view, an IG reset, a replay's long step).
class ExposureAdaptation {
 public:
  // tau_s > 0.
  explicit ExposureAdaptation(double tau_s = kDefaultAdaptationTau_s);
  // The EV100 at time_s (s, any origin, the same each call) adapting to
  // target_ev100 since the previous update.
  double update(double target_ev100, double time_s);
  double ev100() const { return ev100_; }
  double tau_s() const { return tau_s_; }
  // Gaps longer than this many time constants (99.3 % adapted) snap.
  static constexpr double kSnapAfterTaus = 5.0;

 private:
  double tau_s_;
  double ev100_ = 0;
  double time_s_ = 0;
  bool started_ = false;
};

}  // namespace sky::render
