// The Vulkan engine: Vulkan 1.1 core compute only (runs on Mesa's lavapipe),
// the kernels of shaders/gi.comp compiled by glslc at build time and
// embedded. Every buffer is host-visible and coherent, device-local too
// where the device has such memory (lavapipe: all of it; a discrete GPU:
// its BAR heap, falling back to host memory when that is full). A lighting
// update is one command buffer (the levels' cones, their updates, the copies
// of the new light over the old, the precombines, with a barrier between
// kinds), one submit waited on with a fence; GPU timestamps around its work
// give GiTimings::device_seconds, and between the kinds the time per kernel.
#include <cstring>
#include <vector>

#include <vulkan/vulkan.h>

#include "gi_bridge/detail/gi_engine.h"

namespace ldc::detail {
namespace {

const uint32_t kSpvAlpha[] =
#include "gi_kernel1.spv.inc"
    ;
const uint32_t kSpvPrecombine[] =
#include "gi_kernel2.spv.inc"
    ;
const uint32_t kSpvUpdate[] =
#include "gi_kernel3.spv.inc"
    ;
const uint32_t kSpvQuery[] =
#include "gi_kernel4.spv.inc"
    ;
const uint32_t kSpvCones[] =
#include "gi_kernel5.spv.inc"
    ;

constexpr int kBindings = 14;
constexpr int kKernels = 5;  // GiKernel kAlpha .. kCones
constexpr int kGroup = 64;         // local_size_x
constexpr int kMaxGroups = 65535;  // per dispatch (the guaranteed minimum)
// Timestamps per submit: one before the work and one after each run of steps
// of one kind (a full update has 4 such runs); a submit with more runs
// than that times only the whole.
constexpr uint32_t kMaxTimestamps = 64;

Status vk_error(const char* what, VkResult r) {
  return Status(ErrorCode::kIoError, std::string("vulkan: ") + what + " failed (VkResult " + std::to_string(int(r)) + ")");
}

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

class VulkanGi final : public GiEngineBase {
 public:
  explicit VulkanGi(const GiConfig& config) : GiEngineBase(config) {}
  ~VulkanGi() override { destroy(); }
  const char* name() const override { return "vulkan"; }

  Status init(std::string* device_name);

 protected:
  Status upload(const GiLayout& layout) override;
  Status upload_lights(const GiLayout& layout) override;
  Status upload_vmap(const GiLayout& layout) override;
  Status run_steps(const std::vector<GiStep>& steps) override;
  Status set_queries(const std::vector<glm::vec4>& qin) override;
  Status get_queries(std::vector<glm::vec4>& qout, size_t count) override;
  Status read_light(std::vector<glm::vec4>& light) override;

 private:
  Status make_buffer(int binding, VkDeviceSize size, const void* data);
  uint32_t memory_type(uint32_t allowed, VkMemoryPropertyFlags want) const;
  void record(const GiStep& step);
  void free_buffer(Buffer& b);
  void write_descriptors();
  Status make_pipelines();
  // The chosen queue family's timestampValidBits and the device's timestampPeriod.
  Status make_timestamps(uint32_t bits, float period_ns);
  void write_timestamp(uint32_t index);
  // Reads the last submit's timestamps into last_device_seconds_ and, for
  // `runs` (the kernel of each run of steps), last_kernel_seconds_.
  void read_timestamps(const std::vector<GiKernel>& runs);
  void destroy();

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
  VkPipeline pipelines_[kKernels] = {};
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  // Timestamps in each submit's work; none where the queue family has no
  // timestamps (timestampValidBits 0).
  VkQueryPool timestamps_ = VK_NULL_HANDLE;
  uint64_t timestamp_mask_ = 0;
  double timestamp_period_ns_ = 1.0;
  Buffer buffers_[kBindings];
};

// Prefers a discrete GPU, then an integrated one, then anything (lavapipe).
int device_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    default: return 3;
  }
}

Status VulkanGi::init(std::string* device_name) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "ldc gi";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  if (VkResult r = vkCreateInstance(&ici, nullptr, &instance_); r != VK_SUCCESS)
    return Status(ErrorCode::kIoError, "vulkan: no Vulkan instance (VkResult " + std::to_string(int(r)) +
                                           "): is a Vulkan driver (e.g. mesa-vulkan-drivers) installed?");
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  int best_rank = 99;
  uint32_t timestamp_bits = 0;
  float timestamp_period = 1.0f;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(d, &props);
    if (props.apiVersion < VK_API_VERSION_1_1) continue;
    uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> qs(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, qs.data());
    for (uint32_t q = 0; q < nq; ++q) {
      if ((qs[q].queueFlags & VK_QUEUE_COMPUTE_BIT) && device_rank(props.deviceType) < best_rank) {
        best_rank = device_rank(props.deviceType);
        physical_ = d;
        queue_family_ = q;
        timestamp_bits = qs[q].timestampValidBits;
        timestamp_period = props.limits.timestampPeriod;
        if (device_name) *device_name = props.deviceName;
        break;
      }
    }
  }
  if (physical_ == VK_NULL_HANDLE) return Status(ErrorCode::kIoError, "vulkan: no Vulkan 1.1 device with a compute queue");
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  if (VkResult r = vkCreateDevice(physical_, &dci, nullptr, &device_); r != VK_SUCCESS) return vk_error("vkCreateDevice", r);
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = queue_family_;
  if (VkResult r = vkCreateCommandPool(device_, &pci, nullptr, &command_pool_); r != VK_SUCCESS)
    return vk_error("vkCreateCommandPool", r);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = command_pool_;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  if (VkResult r = vkAllocateCommandBuffers(device_, &cai, &cmd_); r != VK_SUCCESS)
    return vk_error("vkAllocateCommandBuffers", r);
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  if (VkResult r = vkCreateFence(device_, &fci, nullptr, &fence_); r != VK_SUCCESS) return vk_error("vkCreateFence", r);
  if (Status s = make_timestamps(timestamp_bits, timestamp_period); !s.ok()) return s;
  return make_pipelines();
}

Status VulkanGi::make_timestamps(uint32_t bits, float period_ns) {
  if (bits == 0) return {};  // GiTimings::device_seconds stays -1
  timestamp_mask_ = bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
  timestamp_period_ns_ = double(period_ns);
  VkQueryPoolCreateInfo qpi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qpi.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qpi.queryCount = kMaxTimestamps;
  if (VkResult r = vkCreateQueryPool(device_, &qpi, nullptr, &timestamps_); r != VK_SUCCESS)
    return vk_error("vkCreateQueryPool", r);
  return {};
}

// The kernel of each run of (non-empty) steps of one kind, in order.
std::vector<GiKernel> kernel_runs(const std::vector<GiStep>& steps) {
  std::vector<GiKernel> runs;
  for (const GiStep& step : steps) {
    if (step.count > 0 && (runs.empty() || runs.back() != step.kernel)) runs.push_back(step.kernel);
  }
  return runs;
}

// Whether a submit of these runs gets a timestamp after each run (else one
// at index 1 after all the work).
bool timed_per_run(const std::vector<GiKernel>& runs) { return !runs.empty() && runs.size() < kMaxTimestamps; }

void VulkanGi::write_timestamp(uint32_t index) {
  if (timestamps_ != VK_NULL_HANDLE && index < kMaxTimestamps)
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_, index);
}

void VulkanGi::read_timestamps(const std::vector<GiKernel>& runs) {
  last_device_seconds_ = -1.0;
  for (double& k : last_kernel_seconds_) k = -1.0;
  if (timestamps_ == VK_NULL_HANDLE) return;
  const bool per_run = timed_per_run(runs);
  const uint32_t count = per_run ? uint32_t(runs.size() + 1) : 2;
  std::vector<uint64_t> t(count, 0);
  if (vkGetQueryPoolResults(device_, timestamps_, 0, count, t.size() * sizeof(uint64_t), t.data(), sizeof(uint64_t),
                            VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT) != VK_SUCCESS)
    return;
  const auto seconds = [&](uint32_t from, uint32_t to) {
    const uint64_t ticks = ((t[to] & timestamp_mask_) - (t[from] & timestamp_mask_)) & timestamp_mask_;
    return double(ticks) * timestamp_period_ns_ * 1e-9;
  };
  last_device_seconds_ = seconds(0, count - 1);
  if (!per_run) return;
  for (double& k : last_kernel_seconds_) k = 0.0;
  for (uint32_t r = 0; r < runs.size(); ++r) last_kernel_seconds_[int(runs[r]) - 1] += seconds(r, r + 1);
}

Status VulkanGi::make_pipelines() {
  VkDescriptorSetLayoutBinding b[kBindings];
  for (int i = 0; i < kBindings; ++i) {
    b[i] = {};
    b[i].binding = uint32_t(i);
    b[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    b[i].descriptorCount = 1;
    b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = kBindings;
  lci.pBindings = b;
  if (VkResult r = vkCreateDescriptorSetLayout(device_, &lci, nullptr, &set_layout_); r != VK_SUCCESS)
    return vk_error("vkCreateDescriptorSetLayout", r);
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(GiPush)};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &set_layout_;
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &push;
  if (VkResult r = vkCreatePipelineLayout(device_, &plci, nullptr, &pipeline_layout_); r != VK_SUCCESS)
    return vk_error("vkCreatePipelineLayout", r);
  const std::pair<const uint32_t*, size_t> code[kKernels] = {
      {kSpvAlpha, sizeof(kSpvAlpha)}, {kSpvPrecombine, sizeof(kSpvPrecombine)}, {kSpvUpdate, sizeof(kSpvUpdate)},
      {kSpvQuery, sizeof(kSpvQuery)}, {kSpvCones, sizeof(kSpvCones)}};
  for (int i = 0; i < kKernels; ++i) {
    VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    smci.codeSize = code[i].second;
    smci.pCode = code[i].first;
    VkShaderModule module;
    if (VkResult r = vkCreateShaderModule(device_, &smci, nullptr, &module); r != VK_SUCCESS)
      return vk_error("vkCreateShaderModule", r);
    VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = module;
    cpci.stage.pName = "main";
    cpci.layout = pipeline_layout_;
    VkResult r = vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &cpci, nullptr, &pipelines_[i]);
    vkDestroyShaderModule(device_, module, nullptr);
    if (r != VK_SUCCESS) return vk_error("vkCreateComputePipelines", r);
  }
  VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindings - 1}};
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 1;
  dpci.poolSizeCount = 2;
  dpci.pPoolSizes = sizes;
  if (VkResult r = vkCreateDescriptorPool(device_, &dpci, nullptr, &pool_); r != VK_SUCCESS)
    return vk_error("vkCreateDescriptorPool", r);
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = pool_;
  dsai.descriptorSetCount = 1;
  dsai.pSetLayouts = &set_layout_;
  if (VkResult r = vkAllocateDescriptorSets(device_, &dsai, &set_); r != VK_SUCCESS)
    return vk_error("vkAllocateDescriptorSets", r);
  return {};
}

void VulkanGi::free_buffer(Buffer& b) {
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
  b = Buffer{};
}

Status VulkanGi::make_buffer(int binding, VkDeviceSize size, const void* data) {
  Buffer& b = buffers_[binding];
  free_buffer(b);
  const VkDeviceSize bytes = size;  // of `data`; the buffer is at least 16
  size = std::max<VkDeviceSize>(size, 16);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size;
  bci.usage = (binding == 0 ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) |
              VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (VkResult r = vkCreateBuffer(device_, &bci, nullptr, &b.buffer); r != VK_SUCCESS) return vk_error("vkCreateBuffer", r);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  VkResult alloc = VK_ERROR_OUT_OF_DEVICE_MEMORY;
  // Device-local first (the kernels read these buffers on every step), then any host-visible memory.
  for (VkMemoryPropertyFlags want : {host | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, host}) {
    mai.memoryTypeIndex = memory_type(req.memoryTypeBits, want);
    if (mai.memoryTypeIndex == UINT32_MAX) continue;
    alloc = vkAllocateMemory(device_, &mai, nullptr, &b.memory);
    if (alloc == VK_SUCCESS) break;
  }
  if (alloc != VK_SUCCESS) return vk_error("vkAllocateMemory (host-visible, coherent)", alloc);
  if (VkResult r = vkBindBufferMemory(device_, b.buffer, b.memory, 0); r != VK_SUCCESS)
    return vk_error("vkBindBufferMemory", r);
  if (VkResult r = vkMapMemory(device_, b.memory, 0, size, 0, &b.mapped); r != VK_SUCCESS) return vk_error("vkMapMemory", r);
  b.size = size;
  std::memset(b.mapped, 0, size_t(size));
  if (data) std::memcpy(b.mapped, data, size_t(bytes));
  return {};
}

uint32_t VulkanGi::memory_type(uint32_t allowed, VkMemoryPropertyFlags want) const {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i) {
    if ((allowed & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
  }
  return UINT32_MAX;
}

void VulkanGi::write_descriptors() {
  VkDescriptorBufferInfo info[kBindings];
  VkWriteDescriptorSet w[kBindings];
  for (int i = 0; i < kBindings; ++i) {
    info[i] = {buffers_[i].buffer, 0, VK_WHOLE_SIZE};
    w[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w[i].dstSet = set_;
    w[i].dstBinding = uint32_t(i);
    w[i].descriptorCount = 1;
    w[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[i].pBufferInfo = &info[i];
  }
  vkUpdateDescriptorSets(device_, kBindings, w, 0, nullptr);
}

template <class T>
VkDeviceSize bytes(const std::vector<T>& v) {
  return VkDeviceSize(v.size() * sizeof(T));
}

Status VulkanGi::upload(const GiLayout& layout) {
  vkDeviceWaitIdle(device_);
  const size_t s = layout.surfaces();
  Status st = make_buffer(0, sizeof(GiParams), &layout.params);
  if (st.ok()) st = make_buffer(1, bytes(layout.occ), layout.occ.data());
  if (st.ok()) st = make_buffer(2, layout.voxels() * 16 * sizeof(float), nullptr);
  if (st.ok()) st = make_buffer(3, bytes(layout.vmap), layout.vmap.data());
  if (st.ok()) st = make_buffer(4, bytes(layout.surf_pos), layout.surf_pos.data());
  if (st.ok()) st = make_buffer(5, bytes(layout.attr), layout.attr.data());
  if (st.ok()) st = make_buffer(6, s * 18 * sizeof(glm::vec4), nullptr);
  if (st.ok()) st = make_buffer(7, s * 18 * sizeof(glm::vec4), nullptr);
  if (st.ok()) st = make_buffer(8, s * 48 * sizeof(glm::vec4), nullptr);
  if (st.ok() && !buffers_[9].buffer) st = make_buffer(9, 32, nullptr);
  if (st.ok() && !buffers_[10].buffer) st = make_buffer(10, 16, nullptr);
  if (st.ok()) st = make_buffer(11, bytes(layout.face_src), layout.face_src.data());
  if (st.ok()) st = make_buffer(12, bytes(layout.light_volume), layout.light_volume.data());
  if (st.ok()) st = make_buffer(13, s * 48 * sizeof(glm::vec4), nullptr);
  if (!st.ok()) return st;
  write_descriptors();
  return {};
}

Status VulkanGi::upload_lights(const GiLayout& layout) {
  // Every run waits for its fence, so no kernel is reading these now.
  std::memcpy(buffers_[0].mapped, &layout.params, sizeof(GiParams));
  if (bytes(layout.light_volume) > buffers_[12].size) return Status(ErrorCode::kInternal, "gi: light volume grew");
  std::memcpy(buffers_[12].mapped, layout.light_volume.data(), size_t(bytes(layout.light_volume)));
  return {};
}

Status VulkanGi::upload_vmap(const GiLayout& layout) {
  // As upload_lights: no kernel is reading it now.
  if (bytes(layout.vmap) > buffers_[3].size) return Status(ErrorCode::kInternal, "gi: voxel map grew");
  std::memcpy(buffers_[3].mapped, layout.vmap.data(), size_t(bytes(layout.vmap)));
  return {};
}

// Records one step: the copy of light_next over light_prev, or the kernel's
// dispatches (items pc.first .. + pc.count, as many dispatches as the
// group-count limit needs).
void VulkanGi::record(const GiStep& step) {
  if (step.kernel == GiKernel::kCommit) {
    const VkDeviceSize unit = 18 * sizeof(glm::vec4);
    const VkBufferCopy region{VkDeviceSize(step.first) * unit, VkDeviceSize(step.first) * unit,
                              VkDeviceSize(step.count) * unit};
    vkCmdCopyBuffer(cmd_, buffers_[7].buffer, buffers_[6].buffer, 1, &region);
    return;
  }
  vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_[int(step.kernel) - 1]);
  const int per_dispatch = kGroup * kMaxGroups;
  for (int done = 0; done < step.count; done += per_dispatch) {
    GiPush push{step.first + done, std::min(per_dispatch, step.count - done), step.level, 0};
    vkCmdPushConstants(cmd_, pipeline_layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
    vkCmdDispatch(cmd_, uint32_t((push.count + kGroup - 1) / kGroup), 1, 1);
  }
}

Status VulkanGi::run_steps(const std::vector<GiStep>& steps) {
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd_, &begin);
  if (timestamps_ != VK_NULL_HANDLE) {
    vkCmdResetQueryPool(cmd_, timestamps_, 0, kMaxTimestamps);
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps_, 0);
  }
  vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_, 0, 1, &set_, 0, nullptr);
  const VkPipelineStageFlags work = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  const std::vector<GiKernel> runs = kernel_runs(steps);
  const bool per_run = timed_per_run(runs);
  GiKernel last = GiKernel::kCommit;
  uint32_t run = 0;
  for (size_t i = 0; i < steps.size(); ++i) {
    if (steps[i].count <= 0) continue;
    // Steps of one kind touch disjoint items; a step of another kind waits
    // for everything before it (reads after writes, and the copies
    // overwrite light the updates read).
    if (run > 0 && steps[i].kernel != last) {
      if (per_run) write_timestamp(run);
      VkMemoryBarrier between{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      between.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
      between.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                              VK_ACCESS_TRANSFER_WRITE_BIT;
      vkCmdPipelineBarrier(cmd_, work, work, 0, 1, &between, 0, nullptr, 0, nullptr);
    }
    if (run == 0 || steps[i].kernel != last) ++run;
    last = steps[i].kernel;
    record(steps[i]);
  }
  // The host reads (memcpy) what the steps wrote: make it visible.
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd_, work, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr, 0, nullptr);
  write_timestamp(per_run ? uint32_t(runs.size()) : 1);
  vkEndCommandBuffer(cmd_);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  if (VkResult r = vkQueueSubmit(queue_, 1, &submit, fence_); r != VK_SUCCESS) return vk_error("vkQueueSubmit", r);
  if (VkResult r = vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX); r != VK_SUCCESS)
    return vk_error("vkWaitForFences", r);
  vkResetFences(device_, 1, &fence_);
  vkResetCommandBuffer(cmd_, 0);
  read_timestamps(runs);
  return {};
}

Status VulkanGi::set_queries(const std::vector<glm::vec4>& qin) {
  const VkDeviceSize in = std::max<VkDeviceSize>(bytes(qin), 32), out = in / 2;
  if (buffers_[9].size < in || buffers_[10].size < out) {
    vkDeviceWaitIdle(device_);
    if (Status s = make_buffer(9, in, nullptr); !s.ok()) return s;
    if (Status s = make_buffer(10, out, nullptr); !s.ok()) return s;
    write_descriptors();
  }
  std::memcpy(buffers_[9].mapped, qin.data(), size_t(bytes(qin)));
  return {};
}

Status VulkanGi::get_queries(std::vector<glm::vec4>& qout, size_t count) {
  qout.resize(count);
  std::memcpy(qout.data(), buffers_[10].mapped, count * sizeof(glm::vec4));
  return {};
}

Status VulkanGi::read_light(std::vector<glm::vec4>& light) {
  light.resize(layout_.surfaces() * 18);
  std::memcpy(light.data(), buffers_[6].mapped, light.size() * sizeof(glm::vec4));
  return {};
}

void VulkanGi::destroy() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    for (Buffer& b : buffers_) free_buffer(b);
    for (VkPipeline p : pipelines_) {
      if (p) vkDestroyPipeline(device_, p, nullptr);
    }
    if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
    if (pipeline_layout_) vkDestroyPipelineLayout(device_, pipeline_layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (timestamps_) vkDestroyQueryPool(device_, timestamps_, nullptr);
    if (command_pool_) vkDestroyCommandPool(device_, command_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  device_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

}  // namespace
}  // namespace ldc::detail

namespace ldc {
Result<std::unique_ptr<GiEngine>> make_vulkan_gi(const GiConfig& config, std::string* device_name) {
  if (Status s = check_gi_config(config); !s.ok()) return s;
  auto engine = std::make_unique<detail::VulkanGi>(config);
  if (Status s = engine->init(device_name); !s.ok()) return s;
  return std::unique_ptr<GiEngine>(std::move(engine));
}
}  // namespace ldc
