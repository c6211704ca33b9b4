// CloudRenderer: wires the GPU context, shape noise, weather texture and cloud
// pass together, and is the module's exception edge: Vulkan-Hpp errors become
// Result errors here and nowhere else.
#include "sky/render/cloud_renderer.hpp"

#include <exception>

#include "sky/core/assert.hpp"

#include "atmosphere_tables.hpp"
#include "cloud_pass.hpp"
#include "frame_setup.hpp"
#include "gpu_context.hpp"
#include "noise_volume.hpp"
#include "weather_texture.hpp"

namespace sky::render {

struct CloudRenderer::Impl {
  // Destroyed in reverse order: the pass (which binds the weather image) before
  // the weather texture, both before the context that owns the device.
  std::unique_ptr<GpuContext> ctx;
  WeatherTexture weather;
  CloudPass pass;
  RenderSettings settings;
  AtmosphereTables atmosphere;  // CPU copy: the frame setup's sky light reads it
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

}  // namespace

CloudRenderer::CloudRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CloudRenderer::CloudRenderer(CloudRenderer&&) noexcept = default;
CloudRenderer& CloudRenderer::operator=(CloudRenderer&&) noexcept = default;
CloudRenderer::~CloudRenderer() = default;

Result<std::unique_ptr<CloudRenderer>> CloudRenderer::create(const RenderSettings& settings) {
  if (auto ok = validateSettings(settings); !ok) return tl::unexpected(ok.error());
  return atVulkanEdge("CloudRenderer::create", [&]() -> Result<std::unique_ptr<CloudRenderer>> {
    auto ctx = GpuContext::create();
    if (!ctx) return tl::unexpected(ctx.error());
    auto weather = WeatherTexture::create(**ctx);
    if (!weather) return tl::unexpected(weather.error());
    const NoiseVolume shape = makeShapeNoise(kShapeNoiseSize, settings.noiseSeed);
    const NoiseVolume detail = makeDetailNoise(kDetailNoiseSize, settings.noiseSeed);
    AtmosphereTables atmosphere = buildAtmosphereTables();
    auto pass = CloudPass::create(**ctx, settings.width, settings.height, shape, detail, atmosphere, *weather);
    if (!pass) return tl::unexpected(pass.error());
    auto impl = std::make_unique<Impl>(
        Impl{std::move(*ctx), std::move(*weather), std::move(*pass), settings, std::move(atmosphere)});
    return std::unique_ptr<CloudRenderer>(new CloudRenderer(std::move(impl)));
  });
}

Result<Image> CloudRenderer::render(const FrameInputs& inputs) {
  SKY_ASSERT(impl_ != nullptr);
  if (auto ok = validateInputs(inputs); !ok) return tl::unexpected(ok.error());
  return atVulkanEdge("CloudRenderer::render", [&]() -> Result<Image> {
    if (auto ok = impl_->weather.update(*impl_->ctx, inputs); !ok) return tl::unexpected(ok.error());
    const FrameSetup setup = prepareFrame(impl_->settings, inputs, impl_->weather.field(), impl_->atmosphere);
    return impl_->pass.run(*impl_->ctx, packFrame(setup));
  });
}

std::string CloudRenderer::deviceName() const { return impl_->ctx->deviceName(); }

const RenderSettings& CloudRenderer::settings() const { return impl_->settings; }

}  // namespace sky::render
