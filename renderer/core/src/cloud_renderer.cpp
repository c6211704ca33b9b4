// CloudRenderer: wires the GPU context, shape noise, weather texture and cloud
// pass together, and is the module's exception edge: Vulkan-Hpp errors become
// Result errors here and nowhere else.
#include "sky/render/cloud_renderer.hpp"

#include <algorithm>
#include <exception>
#include <optional>

#include "sky/core/assert.hpp"

#include "atmosphere_tables.hpp"
#include "blue_noise.hpp"
#include "cloud_pass.hpp"
#include "coverage_mip.hpp"
#include "frame_setup.hpp"
#include "gpu_context.hpp"
#include "near_precip.hpp"
#include "near_precip_pass.hpp"
#include "noise_volume.hpp"
#include "presenter.hpp"
#include "sun_map_plan.hpp"
#include "reproject_pass.hpp"
#include "temporal_plan.hpp"
#include "upscale_pass.hpp"
#include "weather_texture.hpp"

namespace sky::render {

struct CloudRenderer::Impl {
  // Destroyed in reverse order: the presenter, the reprojection pass (which
  // binds the cloud pass's output), the pass (which binds the weather image)
  // before the weather texture, all before the context that owns the device.
  std::unique_ptr<GpuContext> ctx;
  WeatherTexture weather;
  CloudPass pass;
  std::optional<ReprojectPass> reproject;  // with interleaving (settings.temporal.interleave > 1)
  std::optional<UpscalePass> upscale;      // with a resolution divisor (settings.resolution.divisor > 1)
  TemporalPlanner planner;
  std::optional<Presenter> presenter;
  RenderSettings settings;
  AtmosphereTables atmosphere;  // CPU copy: the frame setup's sky light reads it
  std::vector<PassTime> passTimes;
  std::string noiseReport;
  std::uint64_t coverageMipUploads = ~std::uint64_t(0);  // weather uploads the pass's coverage mip is of
  std::vector<float> coverageMip{};                       // its CPU copy (updated per tile as the map is)
  TemporalReport temporal{};  // what the reprojection did with the last frame
  SunMapPlanner sunMaps{};
  SunMapReport sunMap{};      // what became of the sun map in the last frame
  NearPrecipSource nearSource{};
  NearPrecipFrame nearFrame{};  // the last frame's streaks (kept for its buffers)
  NearPrecipReport nearReport{};
  // Built at the first frame with drops to draw (or by buildAllVariants):
  // a renderer that never meets precipitation never compiles its shaders.
  std::optional<NearPrecipPass> nearPass{};

  // The buffer of the image the frame ends with, which the host reads back.
  const GpuBuffer& finalImage() const {
    return upscale ? upscale->output() : reproject ? reproject->output() : pass.output();
  }
  Result<NearPrecipPass*> nearPrecipPass() {
    if (!nearPass) {
      auto created = NearPrecipPass::create(*ctx, settings.width, settings.height, finalImage());
      if (!created) return tl::unexpected(created.error());
      nearPass.emplace(std::move(*created));
    }
    return &*nearPass;
  }
};

namespace {

template <class F>
auto atVulkanEdge(const char* what, F&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const vk::SystemError& e) {
    return fail(ErrorCode::Device, std::string(what) + ": " + e.what());
  } catch (const std::exception& e) {
    return fail(ErrorCode::Device, std::string(what) + ": " + e.what());
  }
}

// llvmpipe's shader compiler (lavapipe's) gives an invocation 65535 loop
// iterations in all, shared by every loop (gallivm's
// LP_MAX_TGSI_LOOP_ITERATIONS); past them every loop exits and the pixel is
// wrong (too bright, or black). The column march nests its steps in the
// primary march's and in the air's: refused where the nesting alone could
// pass half the budget (two layers crossed), with what to lower.
Result<void> checkLoopBudget(const MarchSettings& m, const std::string& device) {
  if (m.sunShadow.method != SunShadow::Column || device.find("llvmpipe") == std::string::npos) return {};
  constexpr std::uint64_t kHalfBudget = 65535 / 2;
  const std::uint64_t air = std::max<std::uint64_t>(m.airSteps == 0 ? 16 : m.airSteps,
                                                    m.airTable.enabled ? m.airTable.slices : 0);
  if (std::uint64_t(m.primarySteps) * m.lightSteps > kHalfBudget || air * m.sunShadow.buildSteps > kHalfBudget)
    return fail(ErrorCode::InvalidArgument,
                "render settings: the column march's primarySteps x lightSteps (" + std::to_string(m.primarySteps) +
                    " x " + std::to_string(m.lightSteps) + ") or air steps x sunShadow.buildSteps (" +
                    std::to_string(air) + " x " + std::to_string(m.sunShadow.buildSteps) + ") is over " +
                    std::to_string(kHalfBudget) + ": " + device +
                    " stops a shader's loops after 65535 iterations in all, and the pixels would be wrong");
  return {};
}

}  // namespace

CloudRenderer::CloudRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CloudRenderer::CloudRenderer(CloudRenderer&&) noexcept = default;
CloudRenderer& CloudRenderer::operator=(CloudRenderer&&) noexcept = default;
CloudRenderer::~CloudRenderer() = default;

Result<std::unique_ptr<CloudRenderer>> CloudRenderer::create(const RenderSettings& settings, const GpuOptions& gpu) {
  if (auto ok = validateSettings(settings); !ok) return tl::unexpected(ok.error());
  return atVulkanEdge("CloudRenderer::create", [&]() -> Result<std::unique_ptr<CloudRenderer>> {
    auto ctx = GpuContext::create(gpu);
    if (!ctx) return tl::unexpected(ctx.error());
    if (auto ok = checkLoopBudget(settings.march, (*ctx)->deviceName()); !ok) return tl::unexpected(ok.error());
    auto weather = WeatherTexture::create(**ctx);
    if (!weather) return tl::unexpected(weather.error());
    std::string noiseReport;
    const NoiseVolume shape = shapeNoiseFor(settings.noiseCacheDir, settings.noiseSeed, &noiseReport);
    const NoiseVolume detail = detailNoiseFor(settings.noiseCacheDir, settings.noiseSeed, &noiseReport);
    AtmosphereTables atmosphere = sharedAtmosphereTables();
    // The size the cloud pass draws (FrameSetup::width).
    const std::uint32_t divisor = settings.resolution.divisor;
    const std::uint32_t smallW = drawnExtent(settings.width, divisor);
    const std::uint32_t smallH = drawnExtent(settings.height, divisor);
    auto pass = CloudPass::create(**ctx, smallW, smallH, shape, detail, atmosphere, *weather,
                                  blueNoiseTile(settings.noiseSeed), settings.march.airTable,
                                  settings.march.sunShadow);
    if (!pass) return tl::unexpected(pass.error());
    std::optional<ReprojectPass> reproject;
    if (settings.temporal.interleave > 1) {
      auto created = ReprojectPass::create(**ctx, smallW, smallH, pass->output(), pass->depth(),
                                           settings.temporal.historyClip > 0, settings.temporal.sharpHistory,
                                           settings.temporal.freshEdges, pass->weatherDescriptor());
      if (!created) return tl::unexpected(created.error());
      reproject.emplace(std::move(*created));
    }
    std::optional<UpscalePass> upscale;
    if (divisor > 1) {
      UpscalePass::Input input;
      if (reproject)
        input.images = &reproject->image();
      else
        input.buffers = {&pass->output(), &pass->depth()};
      auto created = UpscalePass::create(**ctx, smallW, smallH, settings.width, settings.height, input);
      if (!created) return tl::unexpected(created.error());
      upscale.emplace(std::move(*created));
    }
    std::optional<Presenter> presenter;
    if (gpu.window) {
      auto created = Presenter::create(**ctx, *gpu.window);
      if (!created) return tl::unexpected(created.error());
      presenter.emplace(std::move(*created));
    }
    auto impl = std::make_unique<Impl>(Impl{std::move(*ctx), std::move(*weather), std::move(*pass),
                                            std::move(reproject), std::move(upscale),
                                            TemporalPlanner(settings.temporal), std::move(presenter), settings,
                                            std::move(atmosphere), {}, std::move(noiseReport)});
    return std::unique_ptr<CloudRenderer>(new CloudRenderer(std::move(impl)));
  });
}

Result<Image> CloudRenderer::render(const FrameInputs& inputs) {
  SKY_ASSERT(impl_ != nullptr);
  if (auto ok = validateInputs(inputs); !ok) return tl::unexpected(ok.error());
  return atVulkanEdge("CloudRenderer::render", [&]() -> Result<Image> {
    impl_->passTimes.clear();
    const std::uint64_t uploadsBefore = impl_->weather.uploads();
    if (auto ok = impl_->weather.update(*impl_->ctx, inputs); !ok) return tl::unexpected(ok.error());
    // How the map changed since the previous frame, for the history: not
    // at all, in these tiles' texels alone, or (unset) rebuilt.
    WeatherEdit edit;
    edit.field = &impl_->weather.field();
    if (impl_->weather.uploads() == uploadsBefore)
      edit.rects.emplace();
    else if (impl_->weather.uploads() == uploadsBefore + 1 && !impl_->weather.lastUpdate().rebuilt)
      edit.rects = impl_->weather.lastRects();
    edit.largestStep = impl_->weather.lastUpdate().largestStep;
    impl_->passTimes = impl_->weather.lastUploadTimes();
    if (impl_->weather.uploads() != impl_->coverageMipUploads) {  // a new map: its max-coverage mip
      // After one upload of changed tiles only their cells of the mip; a
      // rebuilt map (or a mip missed since) gets a whole new one.
      const bool justTiles = !impl_->weather.lastUpdate().rebuilt && !impl_->coverageMip.empty() &&
                             impl_->weather.uploads() == impl_->coverageMipUploads + 1;
      if (justTiles)
        updateCoverageMip(impl_->coverageMip, impl_->weather.field(), impl_->weather.lastRects());
      else
        impl_->coverageMip = buildCoverageMip(impl_->weather.field());
      impl_->pass.setCoverageMip(impl_->coverageMip);
      impl_->coverageMipUploads = impl_->weather.uploads();
    }
    FrameSetup setup = prepareFrame(impl_->settings, inputs, impl_->weather.field(), impl_->atmosphere);
    impl_->temporal = {};
    impl_->sunMap = {};
    const bool sunMap = sunMapParts(impl_->settings.march.sunShadow.method) > 0;
    if (sunMap) {
      // A weather map rebuilt whole, or tiles that stepped rather than
      // ramped (the history's rule, kMaxRampStep), make the old shadows wrong.
      const auto& update = impl_->weather.lastUpdate();
      const SunMapPlan plan = impl_->sunMaps.plan(setup, inputs.weatherClock_s, impl_->weather.uploads(),
                                                  update.rebuilt || update.largestStep > kMaxRampStep);
      setup.sunMapPlan = plan.frame;
      impl_->sunMap = {plan.builds(), plan.reason, plan.frame.rowBegin, plan.frame.rowEnd, plan.completes};
    }
    // With interleaving the planner chooses this frame's pixels and the
    // reprojection's block; with a divisor the upscale follows.
    CloudPass::Followers next;
    std::optional<TemporalPlan> plan;
    if (impl_->reproject) {
      plan = impl_->planner.plan(setup, inputs, edit);
      setup.interleave = plan->interleave;
      setup.phase = plan->phase;
      setup.freshEdges = plan->freshEdges;
      setup.jitterShift = plan->jitterShift;
      setup.pixelShift = plan->pixelShift;
      setup.pixelJitter = plan->pixelJitter;
      next.reproject = &*impl_->reproject;
      next.reprojectParams = &plan->params;
      next.dropCells = plan->drop.cells;
    }
    const gpu::SkyFrame frame = packFrame(setup);
    gpu::SkyUpscale upscaleBlock{};
    if (impl_->upscale) {
      upscaleBlock = upscaleParams(frame, impl_->settings.resolution, impl_->settings.width, impl_->settings.height);
      next.upscale = &*impl_->upscale;
      next.upscaleParams = &upscaleBlock;
    }
    // The drops near the camera, when it is in precipitation.
    impl_->nearReport = {};
    const NearPrecipInputs nearIn = impl_->nearSource.inputs(impl_->settings, inputs, setup);
    impl_->nearReport.cameraSpeed_mps = glm::length(nearIn.cameraEnu_mps);
    if (nearIn.type != weather::CloudType::None && nearIn.rate_mmph > 0) {
      impl_->nearFrame = buildNearPrecip(nearIn);
      const NearPrecipFrame& near = impl_->nearFrame;
      impl_->nearReport.type = nearIn.type;
      impl_->nearReport.rate_mmph = nearIn.rate_mmph;
      impl_->nearReport.drops = near.population.count;
      impl_->nearReport.capped = near.population.capped || near.entriesCapped;
      impl_->nearReport.streaks = std::uint32_t(near.streaks.size());
      impl_->nearReport.faint = near.faint;
      impl_->nearReport.dropArea_px2 = near.dropArea_px2;
      if (!near.streaks.empty()) {
        auto nearPass = impl_->nearPrecipPass();
        if (!nearPass) return tl::unexpected(nearPass.error());
        next.nearPrecip = *nearPass;
        next.nearPrecipFrame = &near;
      }
    }
    auto image = impl_->pass.run(*impl_->ctx, frame, next);
    if (!image) {
      if (plan) impl_->planner.forget();
      if (sunMap) impl_->sunMaps.forget();
      return image;
    }
    for (auto& t : impl_->pass.lastTimes()) impl_->passTimes.push_back(std::move(t));
    if (plan) {
      impl_->temporal = impl_->reproject->counts();
      impl_->temporal.drawnWhole = plan->drawWhole;
      impl_->temporal.reason = plan->reason;
      impl_->temporal.interleave = plan->interleave;
      impl_->temporal.freshEdges = {plan->freshEdges.x, plan->freshEdges.y, plan->freshEdges.z, plan->freshEdges.w};
      impl_->temporal.freshEdgePixels = plan->freshEdgePixels;
      impl_->temporal.weatherChangedFraction = plan->drop.fraction();
    }
    return image;
  });
}

Result<bool> CloudRenderer::present(const Image& image, double exposure) {
  SKY_ASSERT(impl_ != nullptr);
  if (!impl_->presenter) return fail(ErrorCode::InvalidArgument, "present: this renderer has no window");
  if (image.width != impl_->settings.width || image.height != impl_->settings.height ||
      image.rgba.size() != std::size_t(image.width) * image.height * 4)
    return fail(ErrorCode::InvalidArgument, "present: the image is not a frame of this renderer");
  return atVulkanEdge("CloudRenderer::present", [&]() -> Result<bool> {
    auto shown = impl_->presenter->present(*impl_->ctx, image, exposure);
    if (shown && *shown)
      for (auto& t : impl_->presenter->lastTimes()) impl_->passTimes.push_back(std::move(t));
    return shown;
  });
}

Result<std::size_t> CloudRenderer::buildAllVariants() {
  return atVulkanEdge("building the pass's variants", [&]() -> Result<std::size_t> {
    auto built = impl_->pass.buildAllVariants(*impl_->ctx);
    if (!built) return built;
    const bool had = impl_->nearPass.has_value();
    if (auto near = impl_->nearPrecipPass(); !near) return tl::unexpected(near.error());
    return *built + (had ? 0 : 2);
  });
}

std::size_t CloudRenderer::variantsBuilt() const { return impl_->pass.variantsBuilt() + (impl_->nearPass ? 2 : 0); }

const std::string& CloudRenderer::noiseReport() const { return impl_->noiseReport; }

const std::vector<PassTime>& CloudRenderer::lastPassTimes() const { return impl_->passTimes; }

const SunMapReport& CloudRenderer::lastSunMap() const { return impl_->sunMap; }

const TemporalReport& CloudRenderer::lastTemporal() const { return impl_->temporal; }

const WeatherMapReport& CloudRenderer::lastWeatherMap() const { return impl_->weather.lastUpdate(); }

const NearPrecipReport& CloudRenderer::lastNearPrecip() const { return impl_->nearReport; }

void CloudRenderer::resetHistory(const std::string& reason) { impl_->planner.forget(reason); }

std::vector<std::string> CloudRenderer::takeValidationMessages() { return impl_->ctx->takeValidationMessages(); }

ValidationCounts CloudRenderer::validationCounts() { return impl_->ctx->validationCounts(); }

std::string CloudRenderer::deviceName() const { return impl_->ctx->deviceName(); }

const RenderSettings& CloudRenderer::settings() const { return impl_->settings; }

Result<void> CloudRenderer::setMarch(const MarchSettings& march) {
  RenderSettings next = impl_->settings;
  next.march = march;
  if (auto ok = validateSettings(next); !ok) return ok;
  const AirTableSettings &was = impl_->settings.march.airTable, &now = march.airTable;
  if (was.enabled != now.enabled ||
      (now.enabled && (was.azimuths != now.azimuths || was.zeniths != now.zeniths || was.slices != now.slices)))
    return fail(ErrorCode::InvalidArgument, "CloudRenderer::setMarch: the air table is fixed when the renderer is built");
  if (auto ok = checkLoopBudget(march, impl_->ctx->deviceName()); !ok) return ok;
  const SunMapSettings &sunWas = impl_->settings.march.sunShadow, &sunNow = march.sunShadow;
  if (sunWas.method != sunNow.method || sunWas.size != sunNow.size || sunWas.cascades != sunNow.cascades)
    return fail(ErrorCode::InvalidArgument,
                "CloudRenderer::setMarch: the sun shadow's method and map size are fixed when the renderer is built");
  impl_->settings = next;
  return {};
}

}  // namespace sky::render
