// Image error metrics for skyshell-bench: how far a configuration's image is
// from the `reference` configuration's. Pure CPU code on plain pixel arrays
// (no Vulkan, no renderer types), so it is tested on hand-made images.
// The display transform used for the 8-bit metrics is in display.hpp.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::bench {

// Linear radiance as the renderer returns it: 4 floats per pixel (rgb and the
// view-ray transmittance), row-major, top row first. A view: it does not own
// the pixels.
struct RgbaView {
  std::uint32_t width = 0, height = 0;
  std::span<const float> rgba;  // width * height * 4 values
};

// An 8-bit sRGB image (3 bytes per pixel, row-major, top row first): what a
// user sees in the PNG.
struct Srgb8Image {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3 values
};

// One channel in double precision, row-major (sRGB luma in [0, 255] for SSIM).
struct GrayImage {
  std::uint32_t width = 0, height = 0;
  std::vector<double> v;  // width * height values
};

// Root mean square difference of the linear rgb radiance over every pixel and
// the three colour channels (alpha is not compared). Non-finite pixels make
// the result non-finite (the bench counts them separately). Errors:
// InvalidArgument for images of different or inconsistent sizes.
Result<double> rmseLinear(const RgbaView& a, const RgbaView& b);

// Root mean square difference of two 8-bit images over pixels and rgb, in
// 8-bit levels [0, 255]. Errors as rmseLinear.
Result<double> rmse8(const Srgb8Image& a, const Srgb8Image& b);

// Peak signal-to-noise ratio of two 8-bit images, dB: 10 log10(255^2 / MSE)
// with MSE over pixels and rgb; +infinity for identical images. Errors as
// rmseLinear.
Result<double> psnr(const Srgb8Image& a, const Srgb8Image& b);

// Luma of an sRGB image: Y' = 0.299 R' + 0.587 G' + 0.114 B' on the encoded
// 8-bit values (ITU-R BT.601 weights, as MATLAB's rgb2gray, the input Wang et
// al.'s reference ssim_index.m is usually given for colour images), [0, 255].
GrayImage luma(const Srgb8Image& image);

// Structural similarity, Wang, Bovik, Sheikh, Simoncelli, "Image quality
// assessment: from error visibility to structural similarity", IEEE TIP 13(4),
// 2004, eq. 13 with the paper's parameters: 11x11 circular-symmetric Gaussian
// window, sigma 1.5 px, normalised to sum 1; K1 = 0.01, K2 = 0.03, L = 255.
// The SSIM map is evaluated only where the window lies wholly inside the image
// (MATLAB 'valid', as the paper's ssim_index.m), without the later version's
// automatic downsampling; the index is the map's mean (the paper's MSSIM).
inline constexpr int kSsimWindow = 11;         // px, Wang et al. 2004 section III-C
inline constexpr double kSsimSigma_px = 1.5;   // idem
inline constexpr double kSsimK1 = 0.01, kSsimK2 = 0.03;
inline constexpr double kSsimRange = 255.0;    // L, the dynamic range of 8-bit values

// The SSIM map ((width - 10) x (height - 10) values in [-1, 1]). Errors:
// InvalidArgument for different sizes or an image under 11 px on a side.
Result<GrayImage> ssimMap(const GrayImage& a, const GrayImage& b);
// Mean SSIM of two gray images in [0, 255]; 1 for identical images.
Result<double> ssimGray(const GrayImage& a, const GrayImage& b);
// Mean SSIM of two sRGB images on their luma (see luma()).
Result<double> ssim(const Srgb8Image& a, const Srgb8Image& b);

// Temporal error of a camera path rendered by a configuration (test) against
// the reference's frames of the same path, in 8-bit levels. For each frame t
// >= 1 (index t - 1 in the vectors):
//  * flicker: RMS over pixels and rgb of e_t - e_{t-1}, where e = test -
//    reference; an error that stays put (a bias) costs nothing, an error that
//    changes from frame to frame (noise, shimmering, popping) does.
//  * ghosting: how much of the previous frame the test frame still holds,
//    measured against a baseline B: the least-squares alpha in test_t - B_t =
//    alpha (B_{t-1} - B_t) (0 = no lag, 1 = shows the previous frame; test_t =
//    (1 - a) B_t + a B_{t-1} gives exactly a). B should be what the same
//    configuration shows without history: then spatial error cannot pass for
//    lag (a blurred frame resembles an average of shifted ones, so against the
//    reference a plain lower-resolution render of a moving view scores ~0.1-0.2).
//    Without a baseline, B is the reference. Absent where B barely changes
//    between the two frames (RMS change under kGhostingMinChange levels): no
//    motion, no ghost to see.
inline constexpr double kGhostingMinChange = 0.5;  // 8-bit levels: under half a level, no visible motion
struct TemporalError {
  std::vector<double> flicker;                 // per frame pair, levels
  std::vector<std::optional<double>> ghosting; // per frame pair, fraction
  double meanFlicker = 0, maxFlicker = 0;
  std::optional<double> meanGhosting, maxGhosting;  // over the pairs where it is defined
};
// Errors: InvalidArgument when the sequences (baseline: when given) differ in
// length or frame size, or hold fewer than two frames.
Result<TemporalError> temporalError(std::span<const Srgb8Image> test, std::span<const Srgb8Image> reference,
                                    std::span<const Srgb8Image> baseline = {});

// Error heat map: per pixel the RMS over rgb of the 8-bit difference, mapped
// from 0 (black) through blue, magenta, orange and yellow to white at
// fullScale levels and above, so maps of different configurations compare on
// one scale. Errors as rmse8.
inline constexpr double kHeatMapFullScale = 32.0;  // levels: an eighth of the range is already a glaring error
Result<Srgb8Image> errorHeatMap(const Srgb8Image& test, const Srgb8Image& reference,
                                double fullScale = kHeatMapFullScale);

}  // namespace sky::bench
