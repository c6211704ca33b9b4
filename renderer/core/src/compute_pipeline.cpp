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
  const vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *module, "main");
  p.pipeline = vk::raii::Pipeline(device, nullptr, vk::ComputePipelineCreateInfo({}, stage, *p.layout));
  ctx.name(p.setLayout, (name_ + ".setLayout").c_str());
  ctx.name(p.layout, (name_ + ".layout").c_str());
  ctx.name(p.pipeline, name_.c_str());
  return p;
}

}  // namespace sky::render
