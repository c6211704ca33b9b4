// The cloud pass: one compute dispatch over the image (shaders/clouds.comp),
// after the air table's when the frame has one (shaders/air_table.comp, the
// same descriptor set), with its frame block, shape and detail noise, the atmosphere's
// transmittance and multiple-scattering tables, samplers, output buffers
// (radiance + transmittance, cloud depth), descriptor set, timestamps and
// command buffer. Blocking: run() returns the read-back image.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "atmosphere_tables.hpp"
#include "compute_pipeline.hpp"
#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "near_precip_pass.hpp"
#include "noise_volume.hpp"
#include "reproject_pass.hpp"
#include "upscale_pass.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky_shared.h"
#include "weather_texture.hpp"

namespace sky::render {

class CloudPass {
 public:
  // weather must outlive the pass (its image view is bound once here);
  // blueNoise is the tile (kBlueNoiseSize^2 values) the march's step offsets
  // may come from (MarchSettings::blueNoise).
  // Errors: Io/Malformed for the SPIR-V, Device from the texture uploads;
  // other Vulkan failures throw.
  // airTable sizes the air table's image (a token one when it is off; a
  // frame may then not ask for the table); sunMap the sun map's (a token
  // one without a map method) and fixes the method of every frame.
  static Result<CloudPass> create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                  const NoiseVolume& shape, const NoiseVolume& detail,
                                  const AtmosphereTables& atmosphere, const WeatherTexture& weather,
                                  const std::vector<float>& blueNoise, const AirTableSettings& airTable,
                                  const SunMapSettings& sunMap);

  // The passes that follow the clouds in the same submission, each with
  // its block: the reprojection (with interleaving; without it the frame
  // must draw every pixel), then the upscale (with a resolution divisor).
  // The upscale reads what came before it: its sources are this pass's
  // output, or with a reprojection that pass's outputs 0 and 1, in order.
  struct Followers {
    ReprojectPass* reproject = nullptr;
    const gpu::SkyReproject* reprojectParams = nullptr;
    // A history for the reprojection from another pass's last image of the
    // same size (its radiance + transmittance and cloud depth buffers),
    // copied in first, before this frame's clouds overwrite either.
    std::pair<vk::Buffer, vk::Buffer> seedHistory{};
    // Or the history boxed down from the last full image
    // (ReprojectPass::prepareDownsample, called before the run).
    bool downsampleHistory = false;
    std::span<const std::uint32_t> dropCells;  // the history-drop mask, when reprojectParams->drop.w is set
    UpscalePass* upscale = nullptr;
    const gpu::SkyUpscale* upscaleParams = nullptr;
    // Last, over the image the others left: the drops near the camera.
    NearPrecipPass* nearPrecip = nullptr;
    const NearPrecipFrame* nearPrecipFrame = nullptr;
  };

  // Dispatches one frame and its followers and reads back the image the
  // last of them wrote. Errors: Timeout, Device.
  Result<Image> run(const GpuContext& ctx, const gpu::SkyFrame& frame, const Followers& followers);
  // What the clouds write: radiance + transmittance and cloud depth of the
  // pixels drawn, packed (sky_shared.h, SkyFrame::interleave).
  const GpuBuffer& output() const { return output_; }
  // The weather texture as this pass samples it (its sampler), for the
  // reprojection's reads of the wind map.
  vk::DescriptorImageInfo weatherDescriptor() const {
    return {*weatherSampler_, weatherView_, vk::ImageLayout::eShaderReadOnlyOptimal};
  }
  const GpuBuffer& depth() const { return depth_; }
  // Gives the air table this size (both it and the table the pass was
  // built with enabled): a new image, its old contents are not kept (each
  // frame builds its table). Call between runs. Vulkan failures throw.
  void resizeAirTable(const GpuContext& ctx, const AirTableSettings& airTable);
  // Replaces the max-coverage mip the march reads (coverage_mip.hpp; size
  // kMaxLayers x kCoverageMipSize^2). Call between runs.
  void setCoverageMip(const std::vector<float>& mip);
  // Builds every variant of the pass's shaders not built yet, so that no
  // later run waits for a compile: on lavapipe about 0.2 s a pipeline, and
  // a wind crossfade's or a flash's first frame took 0.5 s longer than the
  // next. Returns how many it built. Errors as run's.
  Result<std::size_t> buildAllVariants(const GpuContext& ctx);
  // How many variants are built (by either way).
  std::size_t variantsBuilt() const;
  // GPU time of the last run's dispatches ("sun-map", "air-table", "clouds", then "reproject", "upscale",
  // "near-precip").
  std::vector<PassTime> lastTimes() const { return timer_.results(); }

 private:
  CloudPass() = default;
  // The shaders of the pass, in the order they run.
  enum class Stage { SunMap, AirTable, Clouds };
  // The variant of a stage's shader for a frame drawing layersDrawn layers,
  // with or without a layer whose wind varies over the map, built now if it
  // is not yet. Errors: Io/Malformed for the SPIR-V; Vulkan failures throw.
  Result<const ComputePipeline*> pipelineFor(const GpuContext& ctx, Stage stage, std::uint32_t layersDrawn,
                                             bool windField, bool lightning = false, bool showers = false);

  // Destroyed in reverse order: fence and command buffer first, the
  // descriptor set before its pool, buffers and images before the samplers
  // and pipeline that reference them in the set layout.
  // The pass's pipelines by variant (cloud_pass.glsl's specialisation
  // constants), built on first use: the clouds' by the layers a frame draws
  // (none: a clear sky; one; several, which shadow each other), the air
  // table's without and with clouds; each of them and the sun map's without
  // and with a wind field (the first index). Set layouts all identical.
  // By wind field, layers drawn (0, 1, more, more with showers under their
  // carrier's cells) and lightning; the sun map's by wind field and showers.
  std::array<std::array<std::array<std::optional<ComputePipeline>, 2>, 4>, 2> cloudPipelines_;
  std::array<std::array<std::optional<ComputePipeline>, 2>, 2> tablePipelines_;
  std::array<std::array<std::optional<ComputePipeline>, 2>, 2> sunMapPipelines_;
  vk::raii::Sampler noiseSampler_{nullptr};
  vk::raii::Sampler airTableSampler_{nullptr};
  vk::raii::Sampler weatherSampler_{nullptr};
  vk::ImageView weatherView_;  // the WeatherTexture's (which outlives this pass)
  vk::raii::Sampler tableSampler_{nullptr};
  GpuImage shape_;
  GpuImage detail_;
  GpuImage transmittance_;
  GpuImage multipleScattering_;
  GpuImage airTable_;  // written by the table pass, sampled by the clouds (eGeneral)
  AirTableSettings airTableSize_;
  GpuImage sunMap_;  // written by the map pass, sampled by the table and the clouds (eGeneral)
  bool sunMapBuilt_ = false;  // it has been used (its contents are kept from then on; see sun_map_plan.hpp)
  SunMapSettings sunMapSize_;
  GpuBuffer uniforms_;  // the frame block (a storage buffer, see clouds.comp)
  GpuBuffer output_;
  GpuBuffer depth_;
  GpuBuffer coverageMip_;  // the weather map's max-coverage mip (host-visible storage buffer)
  GpuBuffer blueNoise_;    // the step offsets' blue-noise tile (blue_noise.hpp)
  vk::raii::DescriptorPool descriptorPool_{nullptr};
  vk::raii::DescriptorSet descriptorSet_{nullptr};
  GpuTimer timer_;
  vk::raii::CommandBuffer commands_{nullptr};
  vk::raii::Fence fence_{nullptr};
  std::uint32_t width_ = 0, height_ = 0;
};

}  // namespace sky::render
