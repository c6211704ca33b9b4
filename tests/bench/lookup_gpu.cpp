// Vulkan harness of the density-lookup micro-benchmark (see lookup_gpu.hpp).
// The module's exception edge: Vulkan-Hpp errors become Result errors here.
#include "lookup_gpu.hpp"

#include <time.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numeric>
#include <optional>

#include <vulkan/vulkan_raii.hpp>

namespace sky::bench {

namespace {

constexpr std::uint32_t kLocalSize = 8;  // lookup_march.comp's workgroup edge
// A dispatch slower than this is a lost device, ns (a 4K march on lavapipe takes seconds).
constexpr std::uint64_t kFenceTimeout_ns = 120'000'000'000ull;
// Permutation stride as a fraction of the tile count (golden-ratio conjugate, lavapipe.md).
constexpr double kStrideFraction = 0.618;

struct Push {
  std::uint32_t image[4];
  std::uint32_t march[4];
  float origin[4];
  float lens[4];
};
static_assert(sizeof(Push) == 64, "push constant block of lookup_march.comp");

double processCpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

std::uint32_t coprimeStride(std::uint32_t n) {
  if (n <= 2) return 1;
  auto s = std::uint32_t(std::lround(kStrideFraction * n));
  while (std::gcd(s, n) != 1) ++s;
  return s;
}

}  // namespace

struct LookupGpu::Impl {
  // Destroyed in reverse order: everything before the device, the device
  // before the instance, the instance before the loader context.
  vk::raii::Context context;
  vk::raii::Instance instance{nullptr};
  vk::raii::PhysicalDevice physical{nullptr};
  vk::raii::Device device{nullptr};
  vk::raii::Queue queue{nullptr};
  vk::raii::CommandPool pool{nullptr};
  vk::raii::Image volume{nullptr};
  vk::raii::DeviceMemory volumeMemory{nullptr};
  vk::raii::ImageView volumeView{nullptr};
  vk::raii::Sampler sampler{nullptr};
  vk::raii::DescriptorSetLayout setLayout{nullptr};
  vk::raii::PipelineLayout layout{nullptr};
  vk::raii::Pipeline pipeline{nullptr};
  vk::raii::DescriptorPool descriptorPool{nullptr};
  vk::raii::DescriptorSet set{nullptr};
  vk::raii::Buffer sums{nullptr};
  vk::raii::DeviceMemory sumsMemory{nullptr};
  vk::raii::QueryPool queries{nullptr};
  vk::raii::CommandBuffer commands{nullptr};
  vk::raii::Fence fence{nullptr};
  vk::DeviceSize sumsSize = 0;
  void* sumsMapped = nullptr;
  std::uint32_t family = 0;
  double timestampPeriod_ns = 1;
  std::string name;

  std::uint32_t memoryType(std::uint32_t bits, vk::MemoryPropertyFlags flags) const {
    const auto props = physical.getMemoryProperties();
    for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i)
      if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & flags) == flags) return i;
    throw vk::OutOfDeviceMemoryError("no memory type with the required properties");
  }

  void submitAndWait(const vk::raii::CommandBuffer& cmd, const vk::raii::Fence& f) {
    device.resetFences(*f);
    const vk::CommandBuffer raw = *cmd;
    queue.submit(vk::SubmitInfo({}, {}, raw), *f);
    if (device.waitForFences(*f, VK_TRUE, kFenceTimeout_ns) != vk::Result::eSuccess)
      throw vk::DeviceLostError("lookup dispatch did not finish");
  }

  void ensureSums(vk::DeviceSize bytes) {
    if (bytes <= sumsSize) return;
    set = nullptr;
    sumsMemory = nullptr;
    sums = vk::raii::Buffer(device, vk::BufferCreateInfo({}, bytes, vk::BufferUsageFlagBits::eStorageBuffer));
    const auto req = sums.getMemoryRequirements();
    sumsMemory = vk::raii::DeviceMemory(
        device, vk::MemoryAllocateInfo(req.size, memoryType(req.memoryTypeBits,
                                                            vk::MemoryPropertyFlagBits::eHostVisible |
                                                                vk::MemoryPropertyFlagBits::eHostCoherent)));
    sums.bindMemory(*sumsMemory, 0);
    sumsMapped = sumsMemory.mapMemory(0, bytes);
    sumsSize = bytes;
    const vk::DescriptorSetLayout raw = *setLayout;
    vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*descriptorPool, raw));
    set = std::move(sets.front());
    const vk::DescriptorImageInfo imageInfo(*sampler, *volumeView, vk::ImageLayout::eShaderReadOnlyOptimal);
    const vk::DescriptorBufferInfo bufferInfo(*sums, 0, bytes);
    const std::array writes{
        vk::WriteDescriptorSet(*set, 0, 0, vk::DescriptorType::eCombinedImageSampler, imageInfo),
        vk::WriteDescriptorSet(*set, 1, 0, vk::DescriptorType::eStorageBuffer, {}, bufferInfo)};
    device.updateDescriptorSets(writes, {});
  }
};

LookupGpu::LookupGpu(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
LookupGpu::~LookupGpu() = default;
std::string LookupGpu::deviceName() const { return impl_->name; }

namespace {

Result<std::vector<std::uint32_t>> readSpirv(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return fail(ErrorCode::Io, path + ": cannot open");
  const std::streamsize bytes = in.tellg();
  if (bytes <= 0 || bytes % 4 != 0) return fail(ErrorCode::Malformed, path + ": not SPIR-V");
  std::vector<std::uint32_t> words(std::size_t(bytes) / 4);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(words.data()), bytes);
  return words;
}

std::optional<std::uint32_t> computeFamily(const vk::raii::PhysicalDevice& d) {
  const auto families = d.getQueueFamilyProperties();
  for (std::uint32_t i = 0; i < families.size(); ++i)
    if ((families[i].queueFlags & vk::QueueFlagBits::eCompute) && families[i].timestampValidBits > 0) return i;
  return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<LookupGpu>> LookupGpu::create(VolumeFormat format, VolumeFilter filter,
                                                     const std::vector<std::uint8_t>& texels,
                                                     const std::string& spirvPath) {
  constexpr std::size_t kTexels = std::size_t(kVolumeSize) * kVolumeSize * kVolumeSize;
  if (texels.size() != kTexels) return fail(ErrorCode::InvalidArgument, "volume needs 128^3 texels");
  auto code = readSpirv(spirvPath);
  if (!code) return tl::unexpected(code.error());
  auto impl = std::make_unique<Impl>();
  Impl& g = *impl;
  try {
    const vk::ApplicationInfo app("sky_lookup_bench", 1, "skyshell", 1, VK_API_VERSION_1_2);
    try {
      g.instance = vk::raii::Instance(g.context, vk::InstanceCreateInfo({}, &app));
    } catch (const vk::SystemError& e) {
      return fail(ErrorCode::NoDevice, std::string("no Vulkan driver: ") + e.what());
    }
    const char* wanted = std::getenv("SKY_VULKAN_DEVICE");
    vk::raii::PhysicalDevices devices(g.instance);
    for (auto& d : devices) {
      const auto props = d.getProperties();
      const std::string name = props.deviceName.data();
      if (props.apiVersion < VK_API_VERSION_1_2 || !computeFamily(d)) continue;
      if (wanted && name.find(wanted) == std::string::npos) continue;
      g.physical = std::move(d);
      g.name = name;
      g.timestampPeriod_ns = props.limits.timestampPeriod;
      break;
    }
    if (g.name.empty()) return fail(ErrorCode::NoDevice, "no Vulkan 1.2 device with compute and timestamps");
    g.family = *computeFamily(g.physical);
    const float priority = 1.0f;
    const vk::DeviceQueueCreateInfo queueInfo({}, g.family, 1, &priority);
    g.device = vk::raii::Device(g.physical, vk::DeviceCreateInfo({}, queueInfo));
    g.queue = vk::raii::Queue(g.device, g.family, 0);
    g.pool = vk::raii::CommandPool(
        g.device, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer, g.family));
    g.fence = vk::raii::Fence(g.device, vk::FenceCreateInfo());

    // The volume, uploaded through a staging buffer.
    const vk::Format vkFormat = format == VolumeFormat::Rgba8 ? vk::Format::eR8G8B8A8Unorm : vk::Format::eR8Unorm;
    const std::size_t texelBytes = format == VolumeFormat::Rgba8 ? 4 : 1;
    const vk::Extent3D extent(kVolumeSize, kVolumeSize, kVolumeSize);
    g.volume = vk::raii::Image(g.device, vk::ImageCreateInfo({}, vk::ImageType::e3D, vkFormat, extent, 1, 1,
                                                             vk::SampleCountFlagBits::e1, vk::ImageTiling::eOptimal,
                                                             vk::ImageUsageFlagBits::eSampled |
                                                                 vk::ImageUsageFlagBits::eTransferDst));
    const auto imageReq = g.volume.getMemoryRequirements();
    g.volumeMemory = vk::raii::DeviceMemory(
        g.device, vk::MemoryAllocateInfo(imageReq.size, g.memoryType(imageReq.memoryTypeBits,
                                                                     vk::MemoryPropertyFlagBits::eDeviceLocal)));
    g.volume.bindMemory(*g.volumeMemory, 0);
    const vk::ImageSubresourceRange range(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);
    g.volumeView = vk::raii::ImageView(g.device, vk::ImageViewCreateInfo({}, *g.volume, vk::ImageViewType::e3D,
                                                                         vkFormat, {}, range));
    const vk::DeviceSize stagingBytes = kTexels * texelBytes;
    vk::raii::Buffer staging(g.device,
                             vk::BufferCreateInfo({}, stagingBytes, vk::BufferUsageFlagBits::eTransferSrc));
    const auto stagingReq = staging.getMemoryRequirements();
    vk::raii::DeviceMemory stagingMemory(
        g.device, vk::MemoryAllocateInfo(stagingReq.size, g.memoryType(stagingReq.memoryTypeBits,
                                                                       vk::MemoryPropertyFlagBits::eHostVisible |
                                                                           vk::MemoryPropertyFlagBits::eHostCoherent)));
    staging.bindMemory(*stagingMemory, 0);
    auto* dst = static_cast<std::uint8_t*>(stagingMemory.mapMemory(0, stagingBytes));
    for (std::size_t i = 0; i < kTexels; ++i) std::memset(dst + i * texelBytes, texels[i], texelBytes);
    stagingMemory.unmapMemory();
    vk::raii::CommandBuffers upload(g.device,
                                    vk::CommandBufferAllocateInfo(*g.pool, vk::CommandBufferLevel::ePrimary, 1));
    vk::raii::CommandBuffer& cmd = upload.front();
    cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTopOfPipe, vk::PipelineStageFlagBits::eTransfer, {}, {}, {},
                        vk::ImageMemoryBarrier({}, vk::AccessFlagBits::eTransferWrite, vk::ImageLayout::eUndefined,
                                               vk::ImageLayout::eTransferDstOptimal, VK_QUEUE_FAMILY_IGNORED,
                                               VK_QUEUE_FAMILY_IGNORED, *g.volume, range));
    cmd.copyBufferToImage(*staging, *g.volume, vk::ImageLayout::eTransferDstOptimal,
                          vk::BufferImageCopy(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0,
                                                                                  0, 1),
                                              {0, 0, 0}, extent));
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, {}, {},
                        vk::ImageMemoryBarrier(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead,
                                               vk::ImageLayout::eTransferDstOptimal,
                                               vk::ImageLayout::eShaderReadOnlyOptimal, VK_QUEUE_FAMILY_IGNORED,
                                               VK_QUEUE_FAMILY_IGNORED, *g.volume, range));
    cmd.end();
    g.submitAndWait(cmd, g.fence);

    const vk::Filter vkFilter = filter == VolumeFilter::Linear ? vk::Filter::eLinear : vk::Filter::eNearest;
    const auto repeat = vk::SamplerAddressMode::eRepeat;
    g.sampler = vk::raii::Sampler(g.device, vk::SamplerCreateInfo({}, vkFilter, vkFilter, vk::SamplerMipmapMode::eNearest,
                                                                  repeat, repeat, repeat, 0.0f, VK_FALSE, 1.0f,
                                                                  VK_FALSE, vk::CompareOp::eNever, 0.0f, 0.0f));
    const std::array bindings{
        vk::DescriptorSetLayoutBinding(0, vk::DescriptorType::eCombinedImageSampler, 1,
                                       vk::ShaderStageFlagBits::eCompute),
        vk::DescriptorSetLayoutBinding(1, vk::DescriptorType::eStorageBuffer, 1, vk::ShaderStageFlagBits::eCompute)};
    g.setLayout = vk::raii::DescriptorSetLayout(g.device, vk::DescriptorSetLayoutCreateInfo({}, bindings));
    const vk::PushConstantRange pushRange(vk::ShaderStageFlagBits::eCompute, 0, sizeof(Push));
    const vk::DescriptorSetLayout rawSetLayout = *g.setLayout;
    g.layout = vk::raii::PipelineLayout(g.device, vk::PipelineLayoutCreateInfo({}, rawSetLayout, pushRange));
    const vk::raii::ShaderModule module(g.device, vk::ShaderModuleCreateInfo({}, *code));
    g.pipeline = vk::raii::Pipeline(
        g.device, nullptr,
        vk::ComputePipelineCreateInfo({}, vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eCompute,
                                                                            *module, "main"),
                                      *g.layout));
    const std::array poolSizes{vk::DescriptorPoolSize(vk::DescriptorType::eCombinedImageSampler, 1),
                               vk::DescriptorPoolSize(vk::DescriptorType::eStorageBuffer, 1)};
    g.descriptorPool = vk::raii::DescriptorPool(
        g.device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, poolSizes));
    g.queries = vk::raii::QueryPool(g.device, vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, 2));
    vk::raii::CommandBuffers commands(g.device,
                                      vk::CommandBufferAllocateInfo(*g.pool, vk::CommandBufferLevel::ePrimary, 1));
    g.commands = std::move(commands.front());
  } catch (const vk::SystemError& e) {
    return fail(ErrorCode::Device, std::string("lookup bench Vulkan setup: ") + e.what());
  }
  return std::unique_ptr<LookupGpu>(new LookupGpu(std::move(impl)));
}

Result<LookupTiming> LookupGpu::run(const LookupDispatch& d, std::vector<float>* sums) {
  Impl& g = *impl_;
  try {
    g.ensureSums(vk::DeviceSize(d.width) * d.height * sizeof(float));
    const std::uint32_t tilesX = (d.width + kLocalSize - 1) / kLocalSize;
    const std::uint32_t tiles = tilesX * ((d.height + kLocalSize - 1) / kLocalSize);
    constexpr double kPi = 3.14159265358979323846;
    const double tanY = std::tan(d.verticalFov_deg * kPi / 360.0);
    // Rays start inside the volume off its lattice so no lookup lands exactly
    // on texel centres (which would make trilinear filtering trivially cheap).
    const Push push{{d.width, d.height, tilesX, tiles},
                    {d.steps, coprimeStride(tiles), 0, 0},
                    {0.313f, 0.271f, 0.437f, float(d.stepTexels / kVolumeSize)},
                    {float(tanY * d.width / d.height), float(tanY), 0, 0}};
    g.commands.reset();
    g.commands.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
    g.commands.resetQueryPool(*g.queries, 0, 2);
    g.commands.bindPipeline(vk::PipelineBindPoint::eCompute, *g.pipeline);
    g.commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *g.layout, 0, *g.set, {});
    g.commands.pushConstants<Push>(*g.layout, vk::ShaderStageFlagBits::eCompute, 0, push);
    g.commands.writeTimestamp(vk::PipelineStageFlagBits::eTopOfPipe, *g.queries, 0);
    g.commands.dispatch(tiles, 1, 1);
    g.commands.writeTimestamp(vk::PipelineStageFlagBits::eBottomOfPipe, *g.queries, 1);
    g.commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {},
                               vk::MemoryBarrier(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead), {},
                               {});
    g.commands.end();
    const double cpu0 = processCpu_ms();
    const auto t0 = std::chrono::steady_clock::now();
    g.submitAndWait(g.commands, g.fence);
    const auto t1 = std::chrono::steady_clock::now();
    LookupTiming t;
    t.cpu_ms = processCpu_ms() - cpu0;
    t.wall_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    const auto [result, stamps] = g.queries.getResults<std::uint64_t>(
        0, 2, 2 * sizeof(std::uint64_t), sizeof(std::uint64_t),
        vk::QueryResultFlagBits::e64 | vk::QueryResultFlagBits::eWait);
    if (result != vk::Result::eSuccess) return fail(ErrorCode::Device, "timestamp query: " + vk::to_string(result));
    t.gpu_ms = double(stamps[1] - stamps[0]) * g.timestampPeriod_ns * 1e-6;
    if (sums) {
      sums->resize(std::size_t(d.width) * d.height);
      std::memcpy(sums->data(), g.sumsMapped, sums->size() * sizeof(float));
    }
    return t;
  } catch (const vk::SystemError& e) {
    return fail(ErrorCode::Device, std::string("lookup dispatch: ") + e.what());
  }
}

}  // namespace sky::bench
