// Image error metrics (see metrics.hpp): RMSE, PSNR, SSIM, temporal error of
// camera paths and the error heat map.
#include "sky/bench/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace sky::bench {

namespace {

std::string sizeText(std::uint32_t w, std::uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

std::size_t pixels(std::uint32_t w, std::uint32_t h) { return std::size_t(w) * h; }

Result<void> sameSize(std::uint32_t aw, std::uint32_t ah, std::uint32_t bw, std::uint32_t bh, const char* what) {
  if (aw != bw || ah != bh)
    return fail(ErrorCode::InvalidArgument,
                std::string(what) + ": images differ in size (" + sizeText(aw, ah) + " and " + sizeText(bw, bh) + ")");
  if (aw == 0 || ah == 0) return fail(ErrorCode::InvalidArgument, std::string(what) + ": empty image");
  return {};
}

Result<void> consistent(const RgbaView& v, const char* what) {
  if (v.rgba.size() != pixels(v.width, v.height) * 4)
    return fail(ErrorCode::InvalidArgument, std::string(what) + ": " + sizeText(v.width, v.height) + " image holds " +
                                                std::to_string(v.rgba.size()) + " values, not 4 per pixel");
  return {};
}

Result<void> consistent(const Srgb8Image& v, const char* what) {
  if (v.rgb.size() != pixels(v.width, v.height) * 3)
    return fail(ErrorCode::InvalidArgument, std::string(what) + ": " + sizeText(v.width, v.height) + " image holds " +
                                                std::to_string(v.rgb.size()) + " bytes, not 3 per pixel");
  return {};
}

Result<void> comparable(const Srgb8Image& a, const Srgb8Image& b, const char* what) {
  if (auto ok = sameSize(a.width, a.height, b.width, b.height, what); !ok) return ok;
  if (auto ok = consistent(a, what); !ok) return ok;
  return consistent(b, what);
}

// Mean squared difference of the 8-bit values, levels^2.
double mse8(const Srgb8Image& a, const Srgb8Image& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = double(a.rgb[i]) - double(b.rgb[i]);
    sum += d * d;
  }
  return sum / double(a.rgb.size());
}

// The normalised 1D Gaussian; the 2D window is its outer product (separable).
std::array<double, kSsimWindow> gaussianWeights() {
  std::array<double, kSsimWindow> w{};
  double sum = 0;
  for (int i = 0; i < kSsimWindow; ++i) {
    const double x = i - kSsimWindow / 2;
    w[std::size_t(i)] = std::exp(-x * x / (2 * kSsimSigma_px * kSsimSigma_px));
    sum += w[std::size_t(i)];
  }
  for (double& v : w) v /= sum;
  return w;
}

// 'Valid' 2D filtering of a W x H plane with the separable Gaussian window:
// output (W - 10) x (H - 10).
std::vector<double> filterValid(const std::vector<double>& in, std::uint32_t w, std::uint32_t h) {
  static const std::array<double, kSsimWindow> g = gaussianWeights();
  const std::uint32_t ow = w - (kSsimWindow - 1), oh = h - (kSsimWindow - 1);
  std::vector<double> rows(std::size_t(ow) * h);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < ow; ++x) {
      double s = 0;
      for (int k = 0; k < kSsimWindow; ++k) s += g[std::size_t(k)] * in[std::size_t(y) * w + x + std::uint32_t(k)];
      rows[std::size_t(y) * ow + x] = s;
    }
  std::vector<double> out(std::size_t(ow) * oh);
  for (std::uint32_t y = 0; y < oh; ++y)
    for (std::uint32_t x = 0; x < ow; ++x) {
      double s = 0;
      for (int k = 0; k < kSsimWindow; ++k) s += g[std::size_t(k)] * rows[(std::size_t(y) + std::uint32_t(k)) * ow + x];
      out[std::size_t(y) * ow + x] = s;
    }
  return out;
}

// Piecewise-linear colour ramp of the heat map, t in [0, 1].
std::array<std::uint8_t, 3> heatColour(double t) {
  struct Stop {
    double t, r, g, b;
  };
  static constexpr std::array<Stop, 6> stops{{{0.0, 0, 0, 0},
                                              {0.2, 30, 40, 200},
                                              {0.4, 190, 40, 190},
                                              {0.6, 250, 120, 30},
                                              {0.8, 255, 230, 40},
                                              {1.0, 255, 255, 255}}};
  t = std::clamp(t, 0.0, 1.0);
  std::size_t i = 1;
  while (i + 1 < stops.size() && t > stops[i].t) ++i;
  const Stop& a = stops[i - 1];
  const Stop& b = stops[i];
  const double f = (t - a.t) / (b.t - a.t);
  auto mix = [f](double u, double v) { return static_cast<std::uint8_t>(std::lround(u + (v - u) * f)); };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

}  // namespace

Result<double> rmseLinear(const RgbaView& a, const RgbaView& b) {
  if (auto ok = sameSize(a.width, a.height, b.width, b.height, "rmseLinear"); !ok) return tl::unexpected(ok.error());
  if (auto ok = consistent(a, "rmseLinear"); !ok) return tl::unexpected(ok.error());
  if (auto ok = consistent(b, "rmseLinear"); !ok) return tl::unexpected(ok.error());
  double sum = 0;
  for (std::size_t i = 0; i < a.rgba.size(); i += 4)
    for (std::size_t c = 0; c < 3; ++c) {
      const double d = double(a.rgba[i + c]) - double(b.rgba[i + c]);
      sum += d * d;
    }
  return std::sqrt(sum / (double(pixels(a.width, a.height)) * 3));
}

Result<double> rmse8(const Srgb8Image& a, const Srgb8Image& b) {
  if (auto ok = comparable(a, b, "rmse8"); !ok) return tl::unexpected(ok.error());
  return std::sqrt(mse8(a, b));
}

Result<double> psnr(const Srgb8Image& a, const Srgb8Image& b) {
  if (auto ok = comparable(a, b, "psnr"); !ok) return tl::unexpected(ok.error());
  const double mse = mse8(a, b);
  if (mse == 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(kSsimRange * kSsimRange / mse);
}

GrayImage luma(const Srgb8Image& image) {
  GrayImage out{image.width, image.height, std::vector<double>(pixels(image.width, image.height))};
  for (std::size_t p = 0; p < out.v.size() && p * 3 + 2 < image.rgb.size(); ++p)
    out.v[p] = 0.299 * image.rgb[p * 3] + 0.587 * image.rgb[p * 3 + 1] + 0.114 * image.rgb[p * 3 + 2];
  return out;
}

Result<GrayImage> ssimMap(const GrayImage& a, const GrayImage& b) {
  if (auto ok = sameSize(a.width, a.height, b.width, b.height, "ssim"); !ok) return tl::unexpected(ok.error());
  if (a.v.size() != pixels(a.width, a.height) || b.v.size() != pixels(b.width, b.height))
    return fail(ErrorCode::InvalidArgument, "ssim: gray image holds the wrong number of values");
  if (a.width < std::uint32_t(kSsimWindow) || a.height < std::uint32_t(kSsimWindow))
    return fail(ErrorCode::InvalidArgument, "ssim: " + sizeText(a.width, a.height) +
                                                " image is smaller than the 11x11 window");
  const std::uint32_t w = a.width, h = a.height;
  std::vector<double> aa(a.v.size()), bb(a.v.size()), ab(a.v.size());
  for (std::size_t i = 0; i < a.v.size(); ++i) {
    aa[i] = a.v[i] * a.v[i];
    bb[i] = b.v[i] * b.v[i];
    ab[i] = a.v[i] * b.v[i];
  }
  const auto muA = filterValid(a.v, w, h), muB = filterValid(b.v, w, h);
  const auto eAA = filterValid(aa, w, h), eBB = filterValid(bb, w, h), eAB = filterValid(ab, w, h);
  const double c1 = (kSsimK1 * kSsimRange) * (kSsimK1 * kSsimRange);
  const double c2 = (kSsimK2 * kSsimRange) * (kSsimK2 * kSsimRange);
  GrayImage map{w - (kSsimWindow - 1), h - (kSsimWindow - 1), std::vector<double>(muA.size())};
  for (std::size_t i = 0; i < muA.size(); ++i) {
    const double ma = muA[i], mb = muB[i];
    const double va = eAA[i] - ma * ma, vb = eBB[i] - mb * mb, cov = eAB[i] - ma * mb;
    map.v[i] = ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
  }
  return map;
}

Result<double> ssimGray(const GrayImage& a, const GrayImage& b) {
  auto map = ssimMap(a, b);
  if (!map) return tl::unexpected(map.error());
  double sum = 0;
  for (double v : map->v) sum += v;
  return sum / double(map->v.size());
}

Result<double> ssim(const Srgb8Image& a, const Srgb8Image& b) {
  if (auto ok = comparable(a, b, "ssim"); !ok) return tl::unexpected(ok.error());
  return ssimGray(luma(a), luma(b));
}

Result<TemporalError> temporalError(std::span<const Srgb8Image> test, std::span<const Srgb8Image> reference,
                                    std::span<const Srgb8Image> baseline) {
  if (baseline.empty()) baseline = reference;
  if (test.size() != reference.size() || test.size() != baseline.size())
    return fail(ErrorCode::InvalidArgument, "temporalError: " + std::to_string(test.size()) + " test frames, " +
                                                std::to_string(reference.size()) + " reference frames and " +
                                                std::to_string(baseline.size()) + " baseline frames");
  if (test.size() < 2) return fail(ErrorCode::InvalidArgument, "temporalError: a path needs at least two frames");
  for (std::size_t t = 0; t < test.size(); ++t) {
    if (auto ok = comparable(test[t], reference[t], "temporalError"); !ok) return tl::unexpected(ok.error());
    if (auto ok = comparable(test[t], baseline[t], "temporalError"); !ok) return tl::unexpected(ok.error());
    if (auto ok = comparable(test[t], test[0], "temporalError"); !ok) return tl::unexpected(ok.error());
  }
  TemporalError out;
  double ghostSum = 0;
  std::size_t ghostCount = 0;
  const std::size_t n = test[0].rgb.size();
  for (std::size_t t = 1; t < test.size(); ++t) {
    double flickerSum = 0, ed = 0, dd = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double eNow = double(test[t].rgb[i]) - double(reference[t].rgb[i]);
      const double ePrev = double(test[t - 1].rgb[i]) - double(reference[t - 1].rgb[i]);
      const double lag = double(test[t].rgb[i]) - double(baseline[t].rgb[i]);
      const double d = double(baseline[t - 1].rgb[i]) - double(baseline[t].rgb[i]);
      flickerSum += (eNow - ePrev) * (eNow - ePrev);
      ed += lag * d;
      dd += d * d;
    }
    const double flicker = std::sqrt(flickerSum / double(n));
    out.flicker.push_back(flicker);
    out.meanFlicker += flicker / double(test.size() - 1);
    out.maxFlicker = std::max(out.maxFlicker, flicker);
    if (dd / double(n) < kGhostingMinChange * kGhostingMinChange) {
      out.ghosting.push_back(std::nullopt);
      continue;
    }
    const double alpha = ed / dd;
    out.ghosting.push_back(alpha);
    ghostSum += alpha;
    ++ghostCount;
    out.maxGhosting = std::max(out.maxGhosting.value_or(alpha), alpha);
  }
  if (ghostCount > 0) out.meanGhosting = ghostSum / double(ghostCount);
  return out;
}

Result<Srgb8Image> errorHeatMap(const Srgb8Image& test, const Srgb8Image& reference, double fullScale) {
  if (auto ok = comparable(test, reference, "errorHeatMap"); !ok) return tl::unexpected(ok.error());
  if (!(fullScale > 0)) return fail(ErrorCode::InvalidArgument, "errorHeatMap: full scale must be positive");
  Srgb8Image out{test.width, test.height, std::vector<std::uint8_t>(test.rgb.size())};
  for (std::size_t p = 0; p * 3 < test.rgb.size(); ++p) {
    double sum = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const double d = double(test.rgb[p * 3 + c]) - double(reference.rgb[p * 3 + c]);
      sum += d * d;
    }
    const auto colour = heatColour(std::sqrt(sum / 3) / fullScale);
    std::copy(colour.begin(), colour.end(), out.rgb.begin() + std::ptrdiff_t(p * 3));
  }
  return out;
}

}  // namespace sky::bench
