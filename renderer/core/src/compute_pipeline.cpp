// Compute pipeline construction (see compute_pipeline.hpp).
#include "compute_pipeline.hpp"

#include "shader_path.hpp"

namespace sky::render {

ComputePipelineBuilder& ComputePipelineBuilder::binding(std::uint32_t index, vk::DescriptorType type) {
  bindings_.emplace_back(index, type, 1, vk::ShaderStageFlagBits::eCompute);
  return *this;
}

ComputePipelineBuilder& ComputePipelineBuilder::shader(std::string fileName) {
  shaderFile_ = std::move(fileName);
  return *this;
}

ComputePipelineBuilder& ComputePipelineBuilder::constants(std::vector<std::uint32_t> values) {
  constants_ = std::move(values);
  return *this;
}

Result<ComputePipeline> ComputePipelineBuilder::build(const GpuContext& ctx) const {
  auto path = findShader(shaderFile_);
  if (!path) return tl::unexpected(path.error());
  auto code = loadSpirv(*path);
  if (!code) return tl::unexpected(code.error());

  const auto& device = ctx.device();
  ComputePipeline p;
  p.setLayout = vk::raii::DescriptorSetLayout(device, vk::DescriptorSetLayoutCreateInfo({}, bindings_));
  const vk::DescriptorSetLayout setLayout = *p.setLayout;
  p.layout = vk::raii::PipelineLayout(device, vk::PipelineLayoutCreateInfo({}, setLayout));
  const vk::raii::ShaderModule module(device, vk::ShaderModuleCreateInfo({}, *code));
  std::vector<vk::SpecializationMapEntry> entries;
  for (std::uint32_t i = 0; i < constants_.size(); ++i)
    entries.emplace_back(i, std::uint32_t(i * sizeof(std::uint32_t)), sizeof(std::uint32_t));
  const vk::SpecializationInfo specialisation(std::uint32_t(entries.size()), entries.data(),
                                              constants_.size() * sizeof(std::uint32_t), constants_.data());
  const vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *module, "main",
                                                constants_.empty() ? nullptr : &specialisation);
  p.pipeline = vk::raii::Pipeline(device, nullptr, vk::ComputePipelineCreateInfo({}, stage, *p.layout));
  ctx.name(p.setLayout, (name_ + ".setLayout").c_str());
  ctx.name(p.layout, (name_ + ".layout").c_str());
  ctx.name(p.pipeline, name_.c_str());
  return p;
}

StorageSet createStorageSet(const GpuContext& ctx, const ComputePipeline& pipeline, const std::string& name,
                            const std::vector<std::pair<std::uint32_t, vk::DescriptorBufferInfo>>& buffers,
                            const std::vector<std::pair<std::uint32_t, vk::DescriptorImageInfo>>& images,
                            const std::vector<std::pair<std::uint32_t, vk::DescriptorImageInfo>>& sampled) {
  const auto& device = ctx.device();
  std::vector<vk::DescriptorPoolSize> sizes;
  if (!buffers.empty()) sizes.emplace_back(vk::DescriptorType::eStorageBuffer, std::uint32_t(buffers.size()));
  if (!images.empty()) sizes.emplace_back(vk::DescriptorType::eStorageImage, std::uint32_t(images.size()));
  if (!sampled.empty())
    sizes.emplace_back(vk::DescriptorType::eCombinedImageSampler, std::uint32_t(sampled.size()));
  StorageSet s;
  s.pool = vk::raii::DescriptorPool(
      device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, sizes));
  ctx.name(s.pool, (name + ".descriptorPool").c_str());
  vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*s.pool, *pipeline.setLayout));
  s.set = std::move(sets[0]);
  ctx.name(s.set, (name + ".set").c_str());
  std::vector<vk::WriteDescriptorSet> writes;
  for (const auto& [binding, info] : buffers)
    writes.emplace_back(*s.set, binding, 0, vk::DescriptorType::eStorageBuffer, nullptr, info);
  for (const auto& [binding, info] : images)
    writes.emplace_back(*s.set, binding, 0, vk::DescriptorType::eStorageImage, info);
  for (const auto& [binding, info] : sampled)
    writes.emplace_back(*s.set, binding, 0, vk::DescriptorType::eCombinedImageSampler, info);
  device.updateDescriptorSets(writes, {});
  return s;
}

}  // namespace sky::render
