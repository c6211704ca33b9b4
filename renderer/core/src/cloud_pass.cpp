// Cloud pass resources and dispatch (see cloud_pass.hpp).
#include "cloud_pass.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <span>
#include <string>

#include "coverage_mip.hpp"
#include "frame_setup.hpp"
#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

vk::raii::Sampler makeSampler(const GpuContext& ctx, vk::SamplerAddressMode mode, const char* debugName) {
  const vk::SamplerCreateInfo info({}, vk::Filter::eLinear, vk::Filter::eLinear, vk::SamplerMipmapMode::eNearest,
                                   mode, mode, mode, 0.0f, VK_FALSE, 1.0f, VK_FALSE, vk::CompareOp::eNever, 0.0f,
                                   0.0f, vk::BorderColor::eFloatTransparentBlack, VK_FALSE);
  vk::raii::Sampler sampler(ctx.device(), info);
  ctx.name(sampler, debugName);
  return sampler;
}

}  // namespace

Result<CloudPass> CloudPass::create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                    const NoiseVolume& shape, const NoiseVolume& detail,
                                    const AtmosphereTables& atmosphere, const WeatherTexture& weather,
                                    const std::vector<float>& blueNoise, const AirTableSettings& airTable,
                                    const SunMapSettings& sunMap) {
  SKY_ASSERT(blueNoise.size() == std::size_t(gpu::kBlueNoiseSize) * gpu::kBlueNoiseSize);
  CloudPass pass;
  pass.width_ = width;
  pass.height_ = height;
  const auto& device = ctx.device();

  pass.airTableSize_ = airTable.enabled ? airTable : AirTableSettings{false, 8, 8, 4};
  pass.sunMapSize_ = sunMap;
  // The one-layer variant without a wind field now (its set layout is the descriptor set's), the
  // others when a frame first needs them.
  auto first = pass.pipelineFor(ctx, Stage::Clouds, 1, false);
  if (!first) return tl::unexpected(first.error());

  pass.noiseSampler_ = makeSampler(ctx, vk::SamplerAddressMode::eRepeat, "sky.noiseSampler");
  pass.weatherSampler_ = makeSampler(ctx, vk::SamplerAddressMode::eClampToBorder, "sky.weatherSampler");
  pass.tableSampler_ = makeSampler(ctx, vk::SamplerAddressMode::eClampToEdge, "sky.tableSampler");
  {
    // Azimuth repeats round the turn; zenith and distance stop at the edge.
    const vk::SamplerCreateInfo info({}, vk::Filter::eLinear, vk::Filter::eLinear, vk::SamplerMipmapMode::eNearest,
                                     vk::SamplerAddressMode::eRepeat, vk::SamplerAddressMode::eClampToEdge,
                                     vk::SamplerAddressMode::eClampToEdge, 0.0f, VK_FALSE, 1.0f, VK_FALSE,
                                     vk::CompareOp::eNever, 0.0f, 0.0f, vk::BorderColor::eFloatTransparentBlack,
                                     VK_FALSE);
    pass.airTableSampler_ = vk::raii::Sampler(device, info);
    ctx.name(pass.airTableSampler_, "sky.airTableSampler");
  }
  // Off: a token image keeps the descriptor valid.
  pass.airTable_ = createStorageVolume(ctx, vk::Format::eR32G32B32A32Sfloat,
                                       vk::Extent3D(pass.airTableSize_.azimuths, pass.airTableSize_.zeniths,
                                                    3 * pass.airTableSize_.slices),
                                       "sky.airTable");
  const std::uint32_t sunParts = sunMapParts(sunMap.method);
  // Two maps: one read while the other is built (sun_map_plan.hpp).
  pass.sunMap_ = sunParts > 0 ? createStorageArray(ctx, vk::Format::eR32G32B32A32Sfloat, sunMap.size, sunMap.size,
                                                   2 * sunMap.cascades * sunParts, "sky.sunMap")
                              : createStorageArray(ctx, vk::Format::eR32G32B32A32Sfloat, 1, 1, 1, "sky.sunMap");

  auto noiseImage = [&](const NoiseVolume& n, const char* name) {
    return createSampledImage(ctx, vk::ImageType::e3D, n.channels == 4 ? vk::Format::eR8G8B8A8Unorm : vk::Format::eR8Unorm,
                              vk::Extent3D(n.size, n.size, n.size), 1, name);
  };
  pass.shape_ = noiseImage(shape, "sky.shapeNoise");
  if (auto ok = uploadImage(ctx, pass.shape_, std::as_bytes(std::span(shape.texels))); !ok)
    return tl::unexpected(ok.error());
  pass.detail_ = noiseImage(detail, "sky.detailNoise");
  if (auto ok = uploadImage(ctx, pass.detail_, std::as_bytes(std::span(detail.texels))); !ok)
    return tl::unexpected(ok.error());
  auto tableImage = [&](const AtmosphereTable& t, const char* name) {
    return createSampledImage(ctx, vk::ImageType::e2D, vk::Format::eR16G16B16A16Sfloat,
                              vk::Extent3D(t.width, t.height, 1), 1, name);
  };
  pass.transmittance_ = tableImage(atmosphere.transmittance, "sky.transmittanceTable");
  if (auto ok = uploadImage(ctx, pass.transmittance_, std::as_bytes(std::span(atmosphere.transmittance.texels))); !ok)
    return tl::unexpected(ok.error());
  pass.multipleScattering_ = tableImage(atmosphere.multipleScattering, "sky.multipleScatteringTable");
  if (auto ok = uploadImage(ctx, pass.multipleScattering_, std::as_bytes(std::span(atmosphere.multipleScattering.texels)));
      !ok)
    return tl::unexpected(ok.error());

  // A storage buffer, not a uniform buffer: see clouds.comp's FrameBlock.
  pass.uniforms_ = createHostBuffer(ctx, sizeof(gpu::SkyFrame), vk::BufferUsageFlagBits::eStorageBuffer, "sky.frameBlock");
  // Transfer sources: the reprojection and the upscale read copies of them
  // (pixel_mirror.hpp).
  const auto output = vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eTransferSrc;
  pass.output_ = createHostBuffer(ctx, vk::DeviceSize(width) * height * 4 * sizeof(float), output, "sky.cloudOutput");
  pass.depth_ = createHostBuffer(ctx, vk::DeviceSize(width) * height * sizeof(float), output, "sky.cloudDepth");
  pass.coverageMip_ = createHostBuffer(ctx, vk::DeviceSize(kCoverageMipFloats * sizeof(float)),
                                       vk::BufferUsageFlagBits::eStorageBuffer, "sky.coverageMip");
  std::memset(pass.coverageMip_.mapped, 0, pass.coverageMip_.size);
  pass.blueNoise_ = createHostBuffer(ctx, vk::DeviceSize(blueNoise.size() * sizeof(float)),
                                     vk::BufferUsageFlagBits::eStorageBuffer, "sky.blueNoise");
  std::memcpy(pass.blueNoise_.mapped, blueNoise.data(), pass.blueNoise_.size);

  const std::array poolSizes{vk::DescriptorPoolSize(vk::DescriptorType::eCombinedImageSampler, 7),
                             vk::DescriptorPoolSize(vk::DescriptorType::eStorageBuffer, 5),
                             vk::DescriptorPoolSize(vk::DescriptorType::eStorageImage, 2)};
  pass.descriptorPool_ = vk::raii::DescriptorPool(
      device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, poolSizes));
  ctx.name(pass.descriptorPool_, "sky.clouds.descriptorPool");
  const vk::DescriptorSetLayout setLayout = *(*first)->setLayout;
  vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*pass.descriptorPool_, setLayout));
  pass.descriptorSet_ = std::move(sets.front());
  ctx.name(pass.descriptorSet_, "sky.clouds.descriptorSet");

  const vk::DescriptorBufferInfo uniformInfo(*pass.uniforms_.buffer, 0, pass.uniforms_.size);
  const vk::DescriptorBufferInfo outputInfo(*pass.output_.buffer, 0, pass.output_.size);
  const vk::DescriptorBufferInfo depthInfo(*pass.depth_.buffer, 0, pass.depth_.size);
  const vk::DescriptorBufferInfo mipInfo(*pass.coverageMip_.buffer, 0, pass.coverageMip_.size);
  const vk::DescriptorBufferInfo blueInfo(*pass.blueNoise_.buffer, 0, pass.blueNoise_.size);
  const vk::DescriptorImageInfo shapeInfo(*pass.noiseSampler_, *pass.shape_.view, vk::ImageLayout::eShaderReadOnlyOptimal);
  const vk::DescriptorImageInfo detailInfo(*pass.noiseSampler_, *pass.detail_.view, vk::ImageLayout::eShaderReadOnlyOptimal);
  const vk::DescriptorImageInfo tableInfo(*pass.tableSampler_, *pass.transmittance_.view,
                                          vk::ImageLayout::eShaderReadOnlyOptimal);
  const vk::DescriptorImageInfo msInfo(*pass.tableSampler_, *pass.multipleScattering_.view,
                                       vk::ImageLayout::eShaderReadOnlyOptimal);
  pass.weatherView_ = *weather.image().view;
  const vk::DescriptorImageInfo weatherInfo = pass.weatherDescriptor();
  const vk::DescriptorImageInfo airOutInfo({}, *pass.airTable_.view, vk::ImageLayout::eGeneral);
  const vk::DescriptorImageInfo airInfo(*pass.airTableSampler_, *pass.airTable_.view, vk::ImageLayout::eGeneral);
  const vk::DescriptorImageInfo sunOutInfo({}, *pass.sunMap_.view, vk::ImageLayout::eGeneral);
  const vk::DescriptorImageInfo sunInfo(*pass.tableSampler_, *pass.sunMap_.view, vk::ImageLayout::eGeneral);
  const vk::DescriptorSet set = *pass.descriptorSet_;
  const std::array writes{
      vk::WriteDescriptorSet(set, gpu::kBindingFrame, 0, vk::DescriptorType::eStorageBuffer, {}, uniformInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingShape, 0, vk::DescriptorType::eCombinedImageSampler, shapeInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingDetail, 0, vk::DescriptorType::eCombinedImageSampler, detailInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingTransmittance, 0, vk::DescriptorType::eCombinedImageSampler, tableInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingMultipleScattering, 0, vk::DescriptorType::eCombinedImageSampler, msInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingWeather, 0, vk::DescriptorType::eCombinedImageSampler, weatherInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingOutput, 0, vk::DescriptorType::eStorageBuffer, {}, outputInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingDepth, 0, vk::DescriptorType::eStorageBuffer, {}, depthInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingCoverageMip, 0, vk::DescriptorType::eStorageBuffer, {}, mipInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingBlueNoise, 0, vk::DescriptorType::eStorageBuffer, {}, blueInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingAirTableOut, 0, vk::DescriptorType::eStorageImage, airOutInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingAirTable, 0, vk::DescriptorType::eCombinedImageSampler, airInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingSunMapOut, 0, vk::DescriptorType::eStorageImage, sunOutInfo),
      vk::WriteDescriptorSet(set, gpu::kBindingSunMap, 0, vk::DescriptorType::eCombinedImageSampler, sunInfo)};
  device.updateDescriptorSets(writes, {});

  pass.timer_ = GpuTimer(ctx, 6, "sky.clouds.timer");
  pass.commands_ = ctx.allocateCommandBuffer();
  ctx.name(pass.commands_, "sky.clouds.commands");
  pass.fence_ = vk::raii::Fence(device, vk::FenceCreateInfo());
  ctx.name(pass.fence_, "sky.clouds.fence");
  return pass;
}

Result<const ComputePipeline*> CloudPass::pipelineFor(const GpuContext& ctx, Stage stage, std::uint32_t layersDrawn,
                                                      bool windField, bool lightning, bool showers) {
  const std::size_t wind = windField ? 1 : 0;
  lightning = lightning && stage == Stage::Clouds;  // the other stages draw no light
  showers = showers && stage != Stage::AirTable && layersDrawn > 1;  // a shower and its carrier: two layers
  std::optional<ComputePipeline>& slot =
      stage == Stage::SunMap     ? sunMapPipelines_[wind][showers ? 1 : 0]
      : stage == Stage::AirTable ? tablePipelines_[wind][layersDrawn > 0 ? 1 : 0]
                                 : cloudPipelines_[wind][std::min<std::uint32_t>(layersDrawn, 2) + (showers ? 1 : 0)]
                                                  [lightning ? 1 : 0];
  if (slot) return &*slot;
  // Every variant of the three shaders gets the same bindings, so their set
  // layouts are identical and one descriptor set serves them all (Vulkan's
  // compatibility rule).
  const char* name = stage == Stage::SunMap ? "sky.sunMap" : (stage == Stage::AirTable ? "sky.airTable" : "sky.clouds");
  const char* shader =
      stage == Stage::SunMap ? "sun_map.comp.spv" : (stage == Stage::AirTable ? "air_table.comp.spv" : "clouds.comp.spv");
  ComputePipelineBuilder builder(std::string(name) + ".layers" + std::to_string(std::min<std::uint32_t>(layersDrawn, 2)) +
                                 (windField ? ".wind" : "") + (lightning ? ".lightning" : "") +
                                 (showers ? ".showers" : ""));
  builder.binding(gpu::kBindingFrame, vk::DescriptorType::eStorageBuffer)
      .binding(gpu::kBindingShape, vk::DescriptorType::eCombinedImageSampler)
      .binding(gpu::kBindingWeather, vk::DescriptorType::eCombinedImageSampler)
      .binding(gpu::kBindingOutput, vk::DescriptorType::eStorageBuffer)
      .binding(gpu::kBindingDetail, vk::DescriptorType::eCombinedImageSampler)
      .binding(gpu::kBindingTransmittance, vk::DescriptorType::eCombinedImageSampler)
      .binding(gpu::kBindingMultipleScattering, vk::DescriptorType::eCombinedImageSampler)
      .binding(gpu::kBindingDepth, vk::DescriptorType::eStorageBuffer)
      .binding(gpu::kBindingCoverageMip, vk::DescriptorType::eStorageBuffer)
      .binding(gpu::kBindingBlueNoise, vk::DescriptorType::eStorageBuffer)
      .binding(gpu::kBindingAirTableOut, vk::DescriptorType::eStorageImage)
      .binding(gpu::kBindingAirTable, vk::DescriptorType::eCombinedImageSampler)
      .binding(gpu::kBindingSunMapOut, vk::DescriptorType::eStorageImage)
      .binding(gpu::kBindingSunMap, vk::DescriptorType::eCombinedImageSampler)
      .shader(shader)
      .constants({layersDrawn > 0 ? 1u : 0u, airTableSize_.enabled ? 1u : 0u, layersDrawn > 1 ? 1u : 0u,
                  std::uint32_t(sunMapSize_.method), windField ? 1u : 0u, lightning ? 1u : 0u, showers ? 1u : 0u});
  auto built = builder.build(ctx);
  if (!built) return tl::unexpected(built.error());
  slot = std::move(*built);
  return &*slot;
}

Result<std::size_t> CloudPass::buildAllVariants(const GpuContext& ctx) {
  const std::size_t before = variantsBuilt();
  for (const bool wind : {false, true}) {
    for (const std::uint32_t layers : {0u, 1u, 2u})
      for (const bool lightning : {false, true})
        for (const bool showers : {false, true})
          if (layers > 1 || !showers)
            if (auto built = pipelineFor(ctx, Stage::Clouds, layers, wind, lightning, showers); !built)
              return tl::unexpected(built.error());
    // As run() asks for them: the table where it is on, the sun map where
    // its method has a map (and only for frames with layers).
    if (airTableSize_.enabled)
      for (const std::uint32_t layers : {0u, 1u})
        if (auto built = pipelineFor(ctx, Stage::AirTable, layers, wind); !built) return tl::unexpected(built.error());
    if (sunMapParts(sunMapSize_.method) > 0)
      for (const std::uint32_t layers : {1u, 2u})
        if (auto built = pipelineFor(ctx, Stage::SunMap, layers, wind, false, layers > 1); !built)
          return tl::unexpected(built.error());
  }
  return variantsBuilt() - before;
}

std::size_t CloudPass::variantsBuilt() const {
  std::size_t n = 0;
  for (const auto& byLayers : cloudPipelines_)
    for (const auto& byLightning : byLayers)
      for (const auto& p : byLightning) n += p.has_value();
  for (const auto& byLayers : tablePipelines_)
    for (const auto& p : byLayers) n += p.has_value();
  for (const auto& byShowers : sunMapPipelines_)
    for (const auto& p : byShowers) n += p.has_value();
  return n;
}

void CloudPass::resizeAirTable(const GpuContext& ctx, const AirTableSettings& airTable) {
  SKY_ASSERT(airTableSize_.enabled && airTable.enabled);
  if (airTable.azimuths == airTableSize_.azimuths && airTable.zeniths == airTableSize_.zeniths &&
      airTable.slices == airTableSize_.slices)
    return;
  // The old image is unused once the last run's fence was waited for.
  airTableSize_ = airTable;
  airTable_ = createStorageVolume(ctx, vk::Format::eR32G32B32A32Sfloat,
                                  vk::Extent3D(airTable.azimuths, airTable.zeniths, 3 * airTable.slices),
                                  "sky.airTable");
  const vk::DescriptorImageInfo outInfo({}, *airTable_.view, vk::ImageLayout::eGeneral);
  const vk::DescriptorImageInfo inInfo(*airTableSampler_, *airTable_.view, vk::ImageLayout::eGeneral);
  const std::array writes{
      vk::WriteDescriptorSet(*descriptorSet_, gpu::kBindingAirTableOut, 0, vk::DescriptorType::eStorageImage, outInfo),
      vk::WriteDescriptorSet(*descriptorSet_, gpu::kBindingAirTable, 0, vk::DescriptorType::eCombinedImageSampler,
                             inInfo)};
  ctx.device().updateDescriptorSets(writes, {});
}

void CloudPass::setCoverageMip(const std::vector<float>& mip) {
  SKY_ASSERT(mip.size() * sizeof(float) == coverageMip_.size);
  std::memcpy(coverageMip_.mapped, mip.data(), coverageMip_.size);
}

Result<Image> CloudPass::run(const GpuContext& ctx, const gpu::SkyFrame& frame, const Followers& next) {
  SKY_ASSERT((next.reproject == nullptr) == (next.reprojectParams == nullptr));
  SKY_ASSERT((next.upscale == nullptr) == (next.upscaleParams == nullptr));
  SKY_ASSERT((next.nearPrecip == nullptr) == (next.nearPrecipFrame == nullptr));
  SKY_ASSERT(next.reproject != nullptr || frame.interleave.x == 1);
  std::memcpy(uniforms_.mapped, &frame, sizeof frame);
  // The variants for the layers this frame draws (with coverage somewhere:
  // the others are skipped either way, so the image is the same).
  std::uint32_t layersDrawn = 0;
  for (std::uint32_t i = 0; i < std::uint32_t(frame.weatherMap.y) && i < gpu::kMaxLayers; ++i)
    layersDrawn += frame.layers[i].ambient.w < 0.5f ? 1 : 0;
  // With the flow's code only where a layer's wind varies over the map or
  // its noise is crossfading from one phase to the other (a fifth of the
  // time for a layer with wind).
  bool windField = false;
  for (std::uint32_t i = 0; i < std::uint32_t(frame.weatherMap.y) && i < gpu::kMaxLayers; ++i) {
    const gpu::vec4& flow = frame.layers[i].flow;
    windField = windField || flow.w > 0.5f || (flow.z > 0.0f && flow.z < 1.0f);
  }
  // With lightning's code only in a frame a flash lights.
  const bool lightning = frame.flashInfo.x > 0.5f || frame.flashInfo.y > 0.5f;
  // With the showers' footprint only where a drawn precipitation layer has
  // a carrier (frame_setup.cpp leaves it -1 when the carrier is not drawn).
  bool showers = false;
  for (std::uint32_t i = 0; i < std::uint32_t(frame.weatherMap.y) && i < gpu::kMaxLayers; ++i)
    showers = showers || (frame.layers[i].ambient.w < 0.5f && frame.layers[i].band.y >= 0.0f);
  auto cloudPipeline = pipelineFor(ctx, Stage::Clouds, layersDrawn, windField, lightning, showers);
  if (!cloudPipeline) return tl::unexpected(cloudPipeline.error());
  const ComputePipeline* tablePipeline = nullptr;
  if (frame.airTable.x > 0) {
    auto built = pipelineFor(ctx, Stage::AirTable, layersDrawn, windField);
    if (!built) return tl::unexpected(built.error());
    tablePipeline = *built;
  }
  SKY_ASSERT(frame.sunMap.x == std::uint32_t(sunMapSize_.method));
  // Rows of a map, where the frame has layers to shadow with it and asks
  // for them.
  const ComputePipeline* sunPipeline = nullptr;
  const std::uint32_t sunRowBegin = std::uint32_t(frame.sunBuildShells.z);
  const std::uint32_t sunRowEnd = std::uint32_t(frame.sunBuildShells.w);
  const std::uint32_t sunCascadesBuilt = frame.sunMapSlots.w - frame.sunMapSlots.z;
  if (sunMapParts(sunMapSize_.method) > 0 && layersDrawn > 0 && sunRowEnd > sunRowBegin && sunCascadesBuilt > 0) {
    SKY_ASSERT(frame.sunMap.y == sunMapSize_.size && frame.sunMap.z == sunMapSize_.cascades);
    SKY_ASSERT(sunRowEnd <= sunMapSize_.size && frame.sunMapSlots.w <= sunMapSize_.cascades);
    auto built = pipelineFor(ctx, Stage::SunMap, layersDrawn, windField, false, showers);
    if (!built) return tl::unexpected(built.error());
    sunPipeline = *built;
  }

  commands_.reset();
  commands_.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  timer_.begin(commands_);
  if (next.seedHistory.first) {
    SKY_ASSERT(next.reproject != nullptr && next.seedHistory.second);
    next.reproject->seedHistory(commands_, next.seedHistory.first, next.seedHistory.second);
  }
  if (next.downsampleHistory) {
    SKY_ASSERT(next.reproject != nullptr && !next.seedHistory.first);
    next.reproject->recordDownsample(commands_);
  }
  // The tables' old contents are never read again: from eUndefined each frame.
  const vk::ImageSubresourceRange whole(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);
  const vk::ImageSubresourceRange allLayers(vk::ImageAspectFlagBits::eColor, 0, 1, 0, sunMap_.layers);
  const auto fresh = [](vk::Image image, const vk::ImageSubresourceRange& range) {
    return vk::ImageMemoryBarrier({}, vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eShaderRead,
                                  vk::ImageLayout::eUndefined, vk::ImageLayout::eGeneral, VK_QUEUE_FAMILY_IGNORED,
                                  VK_QUEUE_FAMILY_IGNORED, image, range);
  };
  // The sun maps keep their contents for later frames (the one read, and the
  // one being built band by band): only their first use starts from nothing.
  const std::array freshImages{fresh(*airTable_.image, whole), fresh(*sunMap_.image, allLayers)};
  commands_.pipelineBarrier(
      vk::PipelineStageFlagBits::eTopOfPipe, vk::PipelineStageFlagBits::eComputeShader, {}, {}, {},
      vk::ArrayProxy<const vk::ImageMemoryBarrier>(sunMapBuilt_ ? 1u : 2u, freshImages.data()));
  if (sunPipeline != nullptr) {
    {
      const auto timed = timer_.section(commands_, "sun-map");
      commands_.bindPipeline(vk::PipelineBindPoint::eCompute, *sunPipeline->pipeline);
      commands_.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *sunPipeline->layout, 0, *descriptorSet_, {});
      const std::uint32_t groups = (sunMapSize_.size + gpu::kLocalSize - 1) / gpu::kLocalSize;
      const std::uint32_t rowGroups = (sunRowEnd - sunRowBegin + gpu::kLocalSize - 1) / gpu::kLocalSize;
      commands_.dispatch(groups, rowGroups, sunCascadesBuilt);
    }
    commands_.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                              {}, {},
                              vk::ImageMemoryBarrier(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead,
                                                     vk::ImageLayout::eGeneral, vk::ImageLayout::eGeneral,
                                                     VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                                     *sunMap_.image, allLayers));
  }
  if (frame.airTable.x > 0) {
    SKY_ASSERT(airTableSize_.enabled && frame.airTable.x == airTableSize_.azimuths &&
               frame.airTable.y == airTableSize_.zeniths && frame.airTable.z == airTableSize_.slices);
    {
      const ComputePipeline& table = *tablePipeline;
      const auto timed = timer_.section(commands_, "air-table");
      commands_.bindPipeline(vk::PipelineBindPoint::eCompute, *table.pipeline);
      commands_.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *table.layout, 0, *descriptorSet_, {});
      commands_.dispatch((frame.airTable.x + gpu::kLocalSize - 1) / gpu::kLocalSize,
                         (frame.airTable.y + gpu::kLocalSize - 1) / gpu::kLocalSize, 1);
    }
    commands_.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                              {}, {},
                              vk::ImageMemoryBarrier(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead,
                                                     vk::ImageLayout::eGeneral, vk::ImageLayout::eGeneral,
                                                     VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                                     *airTable_.image, whole));
  }
  {
    const ComputePipeline& pipeline = **cloudPipeline;
    const auto timed = timer_.section(commands_, "clouds");
    commands_.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline.pipeline);
    commands_.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipeline.layout, 0, *descriptorSet_, {});
    // One workgroup per 8x8 tile, in a 1D grid: the shader maps ids to tiles
    // through the permutation in frame.dispatch.
    commands_.dispatch(frame.image.w, 1, 1);
  }
  if (next.reproject != nullptr) next.reproject->record(commands_, timer_, *next.reprojectParams, next.dropCells);
  if (next.upscale != nullptr)
    next.upscale->record(commands_, timer_, *next.upscaleParams);
  if (next.nearPrecip != nullptr) next.nearPrecip->record(commands_, timer_, *next.nearPrecipFrame);
  if (next.reproject == nullptr && next.upscale == nullptr) {
    const std::array toHost{
        vk::BufferMemoryBarrier(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead,
                                VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *output_.buffer, 0, VK_WHOLE_SIZE),
        vk::BufferMemoryBarrier(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead,
                                VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *depth_.buffer, 0, VK_WHOLE_SIZE)};
    commands_.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, {},
                              toHost, {});
  }
  commands_.end();
  if (auto ok = ctx.submitAndWait(commands_, fence_); !ok) {
    sunMapBuilt_ = false;
    return tl::unexpected(ok.error());
  }
  sunMapBuilt_ = true;

  if (next.upscale != nullptr) return next.upscale->readBack();
  if (next.reproject != nullptr) return next.reproject->readBack();
  SKY_ASSERT(frame.image.x <= width_ && frame.image.y <= height_);
  return readImage(output_, depth_, frame.image.x, frame.image.y);
}

}  // namespace sky::render
