// Contact sheet, video and percentiles for headless replays (see replay_outputs.hpp).
#include "sky/app/replay_outputs.hpp"

#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>

#include "sky/core/assert.hpp"

extern char** environ;

namespace sky::app {

namespace {

// Gap between cells and around the sheet, pixels; its colour (linear, dark grey).
constexpr std::uint32_t kGap_px = 4;
constexpr float kGapRadiance = 0.02f;

}  // namespace

ContactSheet::ContactSheet(std::size_t columns, std::size_t rows, std::uint32_t cellWidth,
                           std::uint32_t sourceWidth, std::uint32_t sourceHeight)
    : columns_(columns), rows_(rows), cellW_(cellWidth) {
  SKY_ASSERT(columns > 0 && rows > 0 && cellWidth > 0 && sourceWidth > 0 && sourceHeight > 0);
  cellH_ = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(
                                          std::lround(double(cellWidth) * sourceHeight / sourceWidth)));
  sheet_.width = static_cast<std::uint32_t>(columns) * (cellW_ + kGap_px) + kGap_px;
  sheet_.height = static_cast<std::uint32_t>(rows) * (cellH_ + kGap_px) + kGap_px;
  sheet_.rgba.assign(std::size_t(sheet_.width) * sheet_.height * 4, kGapRadiance);
  for (std::size_t i = 3; i < sheet_.rgba.size(); i += 4) sheet_.rgba[i] = 1.0f;
}

std::vector<std::size_t> ContactSheet::pick(std::size_t frameCount, std::size_t cells) {
  std::vector<std::size_t> out;
  if (frameCount == 0 || cells == 0) return out;
  const std::size_t n = std::min(frameCount, cells);
  for (std::size_t k = 0; k < n; ++k)
    out.push_back(n == 1 ? 0 : static_cast<std::size_t>(std::llround(double(k) * double(frameCount - 1) / double(n - 1))));
  return out;
}

void ContactSheet::add(const render::Image& frame, double exposure) {
  if (added_ >= columns_ * rows_ || frame.width == 0 || frame.height == 0) return;
  const std::uint32_t x0 = kGap_px + static_cast<std::uint32_t>(added_ % columns_) * (cellW_ + kGap_px);
  const std::uint32_t y0 = kGap_px + static_cast<std::uint32_t>(added_ / columns_) * (cellH_ + kGap_px);
  ++added_;
  // Box filter: each cell pixel averages the finite source pixels it covers.
  for (std::uint32_t y = 0; y < cellH_; ++y) {
    const std::uint32_t sy0 = y * frame.height / cellH_;
    const std::uint32_t sy1 = std::max(sy0 + 1, (y + 1) * frame.height / cellH_);
    for (std::uint32_t x = 0; x < cellW_; ++x) {
      const std::uint32_t sx0 = x * frame.width / cellW_;
      const std::uint32_t sx1 = std::max(sx0 + 1, (x + 1) * frame.width / cellW_);
      double sum[4] = {0, 0, 0, 0};
      std::size_t n = 0;
      for (std::uint32_t sy = sy0; sy < std::min(sy1, frame.height); ++sy)
        for (std::uint32_t sx = sx0; sx < std::min(sx1, frame.width); ++sx) {
          const float* p = &frame.rgba[(std::size_t(sy) * frame.width + sx) * 4];
          if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && std::isfinite(p[3]))) continue;
          for (int c = 0; c < 4; ++c) sum[c] += p[c];
          ++n;
        }
      float* q = &sheet_.rgba[(std::size_t(y0 + y) * sheet_.width + (x0 + x)) * 4];
      for (int c = 0; c < 4; ++c) q[c] = n ? static_cast<float>(sum[c] / double(n) * (c < 3 ? exposure : 1.0)) : 0.0f;
    }
  }
}

Result<void> encodeVideo(const std::string& framesDirectory, double fps, const std::string& mp4Path) {
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.4f", fps);
  const std::string input = framesDirectory + "/frame_%06d.png";
  std::vector<std::string> args = {"ffmpeg", "-nostdin", "-loglevel", "error", "-y", "-framerate", rate,
                                   "-i", input, "-c:v", "libx264", "-pix_fmt", "yuv420p", "-vf",
                                   "scale=trunc(iw/2)*2:trunc(ih/2)*2", mp4Path};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (const int e = ::posix_spawnp(&pid, "ffmpeg", nullptr, nullptr, argv.data(), environ); e != 0)
    return fail(ErrorCode::Io, "cannot run ffmpeg (is it installed?): error " + std::to_string(e));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return fail(ErrorCode::Io, "waiting for ffmpeg: error " + std::to_string(errno));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return fail(ErrorCode::Io, "ffmpeg failed encoding " + input + " into " + mp4Path + " (status " +
                                   std::to_string(status) + ")");
  return {};
}

Percentiles percentiles(std::vector<double> samples) {
  Percentiles p;
  if (samples.empty()) return p;
  std::sort(samples.begin(), samples.end());
  auto rank = [&](double q) {
    const auto k = static_cast<std::size_t>(std::ceil(q * double(samples.size())));
    return samples[std::clamp<std::size_t>(k, 1, samples.size()) - 1];
  };
  p.p50 = rank(0.50);
  p.p90 = rank(0.90);
  p.p99 = rank(0.99);
  double sum = 0;
  for (double v : samples) sum += v;
  p.mean = sum / double(samples.size());
  p.max = samples.back();
  return p;
}

}  // namespace sky::app
