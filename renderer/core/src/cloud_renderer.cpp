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

// The passes after the clouds for one way of drawing the image (the
// interleave's history, the resolution divisor), and the drops near the
// camera over the image they end with.
struct FollowerChain {
  std::uint32_t divisor = 1;
  bool interleaved = false;
  // What the reprojection's shader was built with (TemporalSettings).
  bool historyClip = false, sharpHistory = false, freshEdges = false;
  std::optional<ReprojectPass> reproject;  // with interleaving
  std::optional<UpscalePass> upscale;      // with a divisor
  // Built at the first frame with drops to draw (or by buildAllVariants):
  // a renderer that never meets precipitation never compiles its shaders.
  std::optional<NearPrecipPass> nearPass;

  bool drawsLike(const RenderSettings& s) const {
    const TemporalSettings& t = s.temporal;
    return divisor == s.resolution.divisor && interleaved == (t.interleave > 1) &&
           (!interleaved || (historyClip == (t.historyClip > 0) && sharpHistory == t.sharpHistory &&
                             freshEdges == t.freshEdges));
  }
  // The last frame's image (radiance + transmittance, cloud depth) at the
  // size the clouds draw: the reprojection's, or the clouds' own.
  std::pair<vk::Buffer, vk::Buffer> smallImage(const CloudPass& pass) const {
    return reproject ? std::pair{*reproject->output().buffer, *reproject->depth().buffer}
                     : std::pair{*pass.output().buffer, *pass.depth().buffer};
  }
  // The buffers of the image the frame ends with (radiance + transmittance,
  // cloud depth; full size), which the host reads back.
  std::pair<const GpuBuffer*, const GpuBuffer*> finalImage(const CloudPass& pass) const {
    if (upscale) return {&upscale->output(), &upscale->depth()};
    if (reproject) return {&reproject->output(), &reproject->depth()};
    return {&pass.output(), &pass.depth()};
  }
};

namespace {

// The chain for drawing with `settings`, its passes reading `pass`'s output.
Result<std::unique_ptr<FollowerChain>> buildChain(const GpuContext& ctx, const CloudPass& pass,
                                                  const RenderSettings& settings) {
  auto chain = std::make_unique<FollowerChain>();
  const TemporalSettings& t = settings.temporal;
  chain->divisor = settings.resolution.divisor;
  chain->interleaved = t.interleave > 1;
  chain->historyClip = chain->interleaved && t.historyClip > 0;
  chain->sharpHistory = chain->interleaved && t.sharpHistory;
  chain->freshEdges = chain->interleaved && t.freshEdges;
  // The size the cloud pass draws (FrameSetup::width).
  const std::uint32_t smallW = drawnExtent(settings.width, chain->divisor);
  const std::uint32_t smallH = drawnExtent(settings.height, chain->divisor);
  if (chain->interleaved) {
    auto created = ReprojectPass::create(ctx, smallW, smallH, pass.output(), pass.depth(), chain->historyClip,
                                         chain->sharpHistory, chain->freshEdges, pass.weatherDescriptor());
    if (!created) return tl::unexpected(created.error());
    chain->reproject.emplace(std::move(*created));
  }
  if (chain->divisor > 1) {
    UpscalePass::Input input;
    if (chain->reproject)
      input.images = &chain->reproject->image();
    else
      input.buffers = {&pass.output(), &pass.depth()};
    auto created = UpscalePass::create(ctx, smallW, smallH, settings.width, settings.height, input);
    if (!created) return tl::unexpected(created.error());
    chain->upscale.emplace(std::move(*created));
  }
  return chain;
}

}  // namespace

struct CloudRenderer::Impl {
  // Destroyed in reverse order: the presenter, the chains (whose
  // reprojection and upscale bind the cloud pass's output), the pass (which
  // binds the weather image) before the weather texture, all before the
  // context that owns the device.
  std::unique_ptr<GpuContext> ctx;
  WeatherTexture weather;
  CloudPass pass;
  // The ways of drawing built so far (setLevel), the current one first.
  std::vector<std::unique_ptr<FollowerChain>> chains;
  // The chain the last frame ended with (null before the first): a change
  // of chain carries its history over, or draws the frame whole.
  const FollowerChain* lastChain = nullptr;
  bool lastStreaks = false;  // the last frame drew drops near the camera over its image
  TemporalPlanner planner;
  std::optional<Presenter> presenter;
  RenderSettings settings;
  // The cloud pass's size as built: no level draws more.
  std::uint32_t builtDivisor = 1;
  AtmosphereTables atmosphere;  // CPU copy: the frame setup's sky light reads it
  std::vector<PassTime> passTimes{};
  std::string noiseReport{};
  std::uint64_t coverageMipUploads = ~std::uint64_t(0);  // weather uploads the pass's coverage mip is of
  std::vector<float> coverageMip{};                       // its CPU copy (updated per tile as the map is)
  TemporalReport temporal{};  // what the reprojection did with the last frame
  SunMapPlanner sunMaps{};
  SunMapReport sunMap{};      // what became of the sun map in the last frame
  NearPrecipSource nearSource{};
  NearPrecipFrame nearFrame{};  // the last frame's streaks (kept for its buffers)
  NearPrecipReport nearReport{};
  // The planner follows every frame, with a history or not (setLevel).
  bool plansAlways = false;

  FollowerChain& chain() { return *chains.front(); }
  Result<NearPrecipPass*> nearPrecipPass() {
    FollowerChain& c = chain();
    if (!c.nearPass) {
      auto created = NearPrecipPass::create(*ctx, settings.width, settings.height, *c.finalImage(pass).first);
      if (!created) return tl::unexpected(created.error());
      c.nearPass.emplace(std::move(*created));
    }
    return &*c.nearPass;
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
    auto pass = CloudPass::create(**ctx, drawnExtent(settings.width, settings.resolution.divisor),
                                  drawnExtent(settings.height, settings.resolution.divisor), shape, detail,
                                  atmosphere, *weather, blueNoiseTile(settings.noiseSeed), settings.march.airTable,
                                  settings.march.sunShadow);
    if (!pass) return tl::unexpected(pass.error());
    auto chain = buildChain(**ctx, *pass, settings);
    if (!chain) return tl::unexpected(chain.error());
    std::optional<Presenter> presenter;
    if (gpu.window) {
      auto created = Presenter::create(**ctx, *gpu.window);
      if (!created) return tl::unexpected(created.error());
      presenter.emplace(std::move(*created));
    }
    std::vector<std::unique_ptr<FollowerChain>> chains;
    chains.push_back(std::move(*chain));
    auto impl = std::make_unique<Impl>(Impl{std::move(*ctx), std::move(*weather), std::move(*pass), std::move(chains),
                                            nullptr, false, TemporalPlanner(settings.temporal), std::move(presenter),
                                            settings, settings.resolution.divisor, std::move(atmosphere)});
    impl->noiseReport = std::move(noiseReport);
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
      impl_->sunMap = {plan.builds(),          plan.reason,           plan.frame.rowBegin, plan.frame.rowEnd,
                       plan.frame.firstCascade, plan.frame.endCascade, plan.completes};
    }
    // With interleaving the planner chooses this frame's pixels and the
    // reprojection's block; with a divisor the upscale follows.
    CloudPass::Followers next;
    std::optional<TemporalPlan> plan;
    FollowerChain& chain = impl_->chain();
    // A change of the way of drawing (setLevel): the history carries over
    // from the last frame's image, copied at the same size (before the
    // clouds overwrite it), else its full image boxed to the new way's size
    // (box 1 at full size: the upscaled image as it is). None when the
    // drops near the camera were drawn over the last image (the history
    // would keep them).
    if (chain.reproject && impl_->lastChain != nullptr && impl_->lastChain != &chain) {
      const FollowerChain& lastChain = *impl_->lastChain;
      if (impl_->lastStreaks) {
        impl_->planner.forget("drawn another way, after drops near the camera");
      } else if (lastChain.divisor == chain.divisor) {
        next.seedHistory = lastChain.smallImage(impl_->pass);
      } else {
        const auto [colour, depth] = lastChain.finalImage(impl_->pass);
        if (auto ok = chain.reproject->prepareDownsample(*impl_->ctx, *colour, *depth, impl_->settings.width,
                                                         impl_->settings.height, chain.divisor);
            !ok)
          return tl::unexpected(ok.error());
        next.downsampleHistory = true;
      }
    }
    // Without interleaving the planner runs only once the way of drawing
    // may change: it then knows the previous frame when a level with a
    // history follows.
    if (chain.reproject || impl_->plansAlways) {
      const TemporalPlan planned = impl_->planner.plan(setup, inputs, edit);
      if (chain.reproject) plan = planned;
    }
    if (chain.reproject) {
      setup.interleave = plan->interleave;
      setup.phase = plan->phase;
      setup.freshEdges = plan->freshEdges;
      setup.jitterShift = plan->jitterShift;
      setup.pixelShift = plan->pixelShift;
      setup.pixelJitter = plan->pixelJitter;
      next.reproject = &*chain.reproject;
      next.reprojectParams = &plan->params;
      next.dropCells = plan->drop.cells;
    }
    const gpu::SkyFrame frame = packFrame(setup);
    gpu::SkyUpscale upscaleBlock{};
    if (chain.upscale) {
      upscaleBlock = upscaleParams(frame, impl_->settings.resolution, impl_->settings.width, impl_->settings.height);
      next.upscale = &*chain.upscale;
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
      impl_->planner.forget();
      impl_->lastChain = nullptr;
      if (sunMap) impl_->sunMaps.forget();
      return image;
    }
    impl_->lastChain = &chain;
    impl_->lastStreaks = next.nearPrecip != nullptr;
    for (auto& t : impl_->pass.lastTimes()) impl_->passTimes.push_back(std::move(t));
    if (plan) {
      impl_->temporal = chain.reproject->counts();
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
    const bool had = impl_->chain().nearPass.has_value();
    if (auto near = impl_->nearPrecipPass(); !near) return tl::unexpected(near.error());
    return *built + (had ? 0 : 2);
  });
}

std::size_t CloudRenderer::variantsBuilt() const {
  return impl_->pass.variantsBuilt() + (impl_->chains.front()->nearPass ? 2 : 0);
}

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
  return setLevel(march, impl_->settings.temporal, impl_->settings.resolution);
}

Result<void> CloudRenderer::setLevel(const MarchSettings& march, const TemporalSettings& temporal,
                                     const ResolutionSettings& resolution) {
  RenderSettings next = impl_->settings;
  next.march = march;
  next.temporal = temporal;
  next.resolution = resolution;
  if (auto ok = validateSettings(next); !ok) return ok;
  if (impl_->settings.march.airTable.enabled != march.airTable.enabled)
    return fail(ErrorCode::InvalidArgument,
                "CloudRenderer::setLevel: whether the air table is on is fixed when the renderer is built");
  if (auto ok = checkLoopBudget(march, impl_->ctx->deviceName()); !ok) return ok;
  const SunMapSettings &sunWas = impl_->settings.march.sunShadow, &sunNow = march.sunShadow;
  if (sunWas.method != sunNow.method || sunWas.size != sunNow.size || sunWas.cascades != sunNow.cascades)
    return fail(ErrorCode::InvalidArgument,
                "CloudRenderer::setLevel: the sun shadow's method and map size are fixed when the renderer is built");
  // The cloud pass's buffers hold the image at the divisor it was built
  // with; a multiple of it draws fewer pixels into them.
  if (resolution.divisor % impl_->builtDivisor != 0)
    return fail(ErrorCode::InvalidArgument, "CloudRenderer::setLevel: resolution divisor " +
                                                std::to_string(resolution.divisor) + " draws more pixels than the " +
                                                std::to_string(impl_->builtDivisor) + " the renderer was built with");
  return atVulkanEdge("CloudRenderer::setLevel", [&]() -> Result<void> {
    auto& chains = impl_->chains;
    auto found = std::find_if(chains.begin(), chains.end(),
                              [&](const std::unique_ptr<FollowerChain>& c) { return c->drawsLike(next); });
    if (found == chains.end()) {
      auto built = buildChain(*impl_->ctx, impl_->pass, next);
      if (!built) return tl::unexpected(built.error());
      chains.push_back(std::move(*built));
      found = chains.end() - 1;
    }
    std::rotate(chains.begin(), found, found + 1);
    if (march.airTable.enabled) impl_->pass.resizeAirTable(*impl_->ctx, march.airTable);
    impl_->settings = next;
    impl_->planner.setSettings(temporal);
    impl_->plansAlways = true;
    return {};
  });
}

}  // namespace sky::render
