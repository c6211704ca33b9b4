// One builder for every compute pass: descriptor bindings + a SPIR-V file in,
// descriptor set layout, pipeline layout and pipeline out, all debug-named.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu_context.hpp"

namespace sky::render {

struct ComputePipeline {
  // Destroyed in reverse order: pipeline, then its layout, then the set layout.
  vk::raii::DescriptorSetLayout setLayout{nullptr};
  vk::raii::PipelineLayout layout{nullptr};
  vk::raii::Pipeline pipeline{nullptr};
};

class ComputePipelineBuilder {
 public:
  explicit ComputePipelineBuilder(std::string name) : name_(std::move(name)) {}

  // Adds a compute-stage binding in set 0 (count 1).
  ComputePipelineBuilder& binding(std::uint32_t index, vk::DescriptorType type);
  // SPIR-V file name, looked up with findShader().
  ComputePipelineBuilder& shader(std::string fileName);
  // Specialisation constants: constant_id i takes values[i] (32 bits each;
  // a bool is 0 or 1). Replaces any set before.
  ComputePipelineBuilder& constants(std::vector<std::uint32_t> values);

  // Errors: Io/Malformed from the SPIR-V lookup; Vulkan failures throw.
  Result<ComputePipeline> build(const GpuContext& ctx) const;

  const std::vector<vk::DescriptorSetLayoutBinding>& bindings() const { return bindings_; }

 private:
  std::string name_;
  std::string shaderFile_;
  std::vector<vk::DescriptorSetLayoutBinding> bindings_;
  std::vector<std::uint32_t> constants_;
};

// One descriptor set of a pipeline's layout, from a pool of its own.
struct StorageSet {
  // Destroyed in reverse order: the set before its pool.
  vk::raii::DescriptorPool pool{nullptr};
  vk::raii::DescriptorSet set{nullptr};

  StorageSet() = default;
  StorageSet(StorageSet&&) noexcept = default;
  // Assigned over an older set (a pass rebinding its sources): that set is
  // freed before its pool, which member-wise assignment would free first
  // (lavapipe then crashes freeing the set).
  StorageSet& operator=(StorageSet&& other) noexcept {
    set = nullptr;
    pool = std::move(other.pool);
    set = std::move(other.set);
    return *this;
  }
};

// The set for a pass that binds storage buffers and storage images only
// (the reprojection, the upscale), written with these bindings.
StorageSet createStorageSet(const GpuContext& ctx, const ComputePipeline& pipeline, const std::string& name,
                            const std::vector<std::pair<std::uint32_t, vk::DescriptorBufferInfo>>& buffers,
                            const std::vector<std::pair<std::uint32_t, vk::DescriptorImageInfo>>& images,
                            const std::vector<std::pair<std::uint32_t, vk::DescriptorImageInfo>>& sampled = {});

}  // namespace sky::render
