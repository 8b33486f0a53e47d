// Vulkan compute backend of the RDM bake (include/rdm/vulkan_bake.h, docs/vulkan.md).
//
// Host side: the plan (RDMs, skipped faces, texel jobs), the exact central depths (on the
// CPU, exactCentralDepth: identical to the CPU backend) and the per-texel estimators (double,
// in texel then sample order, as the CPU accumulates) live here; the kernel
// (shaders/bake.comp) traces one path per invocation and writes (radiance, sample weight).
// Paths run in batches; a batch is dispatched again and again until no path is active (an
// invocation suspends its path before lavapipe's loop limit, SPEC section 9).
#include "rdm/vulkan_bake.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>

#include "rdm/bake_stats.h"
#include "rdm/rdm_shared_cpp.h"
#include "rdm/traversal.h"

#if RDM_HAVE_VULKAN
#include <vulkan/vulkan.h>

#include "rdm_spirv.h"
#include "shared/rdm_gpu_layout.h"
#endif

namespace rdm {

Expected<BakeBackend> parseBakeBackend(const std::string& text) {
  if (text == "cpu") return BakeBackend::kCpu;
  if (text == "vulkan") return BakeBackend::kVulkan;
  if (text == "auto") return BakeBackend::kAuto;
  return Status::error("unknown backend '" + text + "': expected cpu, vulkan or auto");
}

const char* bakeBackendName(BakeBackend backend) {
  switch (backend) {
    case BakeBackend::kCpu:
      return "cpu";
    case BakeBackend::kVulkan:
      return "vulkan";
    case BakeBackend::kAuto:
      return "auto";
  }
  return "?";
}

Expected<BakeResult> bakeSceneVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                     const VulkanBakeOptions& options) {
  return bakeRdmsVulkan(world, settings, listRdms(world, settings), options);
}

#if !RDM_HAVE_VULKAN

bool vulkanBackendBuilt() {
  return false;
}
Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices() {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
Expected<BakeResult> bakeRdmsVulkan(const VoxelWorld&, const BakeSettings&,
                                    const std::vector<RdmId>&, const VulkanBakeOptions&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
BackendChoice resolveBakeBackend(BakeBackend requested, const std::string&) {
  if (requested == BakeBackend::kAuto)
    return {BakeBackend::kCpu, "auto: this build has no Vulkan backend"};
  return {requested, "requested"};
}

#else

bool vulkanBackendBuilt() {
  return true;
}

namespace {

using glm::ivec3;
using glm::vec3;

const char* vkResultName(VkResult r) {
  switch (r) {
#define RDM_VK_CASE(x) \
  case x:              \
    return #x;
    RDM_VK_CASE(VK_SUCCESS)
    RDM_VK_CASE(VK_NOT_READY)
    RDM_VK_CASE(VK_TIMEOUT)
    RDM_VK_CASE(VK_INCOMPLETE)
    RDM_VK_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    RDM_VK_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    RDM_VK_CASE(VK_ERROR_INITIALIZATION_FAILED)
    RDM_VK_CASE(VK_ERROR_DEVICE_LOST)
    RDM_VK_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    RDM_VK_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    RDM_VK_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    RDM_VK_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    RDM_VK_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    RDM_VK_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    RDM_VK_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    RDM_VK_CASE(VK_ERROR_FRAGMENTED_POOL)
    RDM_VK_CASE(VK_ERROR_UNKNOWN)
    RDM_VK_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    RDM_VK_CASE(VK_ERROR_INVALID_SHADER_NV)
#undef RDM_VK_CASE
    default:
      return "VkResult (unlisted)";
  }
}

Status vkError(const char* call, VkResult r) {
  std::string msg = std::string("Vulkan: ") + call + " failed: " + vkResultName(r) + " (" +
                    std::to_string(int(r)) + ")";
  if (r == VK_ERROR_DEVICE_LOST)
    msg += ": the device was lost (driver reset or hang); the job failed, retry it";
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY) {
    msg += ": out of memory; try a smaller max_batch_paths or the CPU backend";
  }
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER) msg += ": no Vulkan driver (ICD) is installed";
  return Status::error(msg);
}

#define RDM_VK_TRY(call)                                                     \
  do {                                                                       \
    VkResult rdm_vk_result_ = (call);                                        \
    if (rdm_vk_result_ != VK_SUCCESS) return vkError(#call, rdm_vk_result_); \
  } while (0)

std::string deviceTypeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

int typeRank(const std::string& type) {
  if (type == "discrete-gpu") return 0;
  if (type == "integrated-gpu") return 1;
  if (type == "virtual-gpu") return 2;
  if (type == "cpu") return 3;
  return 4;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct Instance {
  VkInstance handle = VK_NULL_HANDLE;
  ~Instance() {
    if (handle) vkDestroyInstance(handle, nullptr);
  }
};

Status createInstance(Instance& instance) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "rdm-bake";
  app.applicationVersion = 1;
  app.pEngineName = "rdm";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  VkResult r = vkCreateInstance(&info, nullptr, &instance.handle);
  if (r != VK_SUCCESS) {
    instance.handle = VK_NULL_HANDLE;
    return vkError("vkCreateInstance", r);
  }
  return {};
}

Status enumerateDevices(VkInstance instance, std::vector<VkPhysicalDevice>& devices,
                        std::vector<VulkanDeviceInfo>& infos) {
  uint32_t count = 0;
  RDM_VK_TRY(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  devices.resize(count);
  if (count) RDM_VK_TRY(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  devices.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devices[i], &p);
    VulkanDeviceInfo d;
    d.index = int(i);
    d.name = p.deviceName;
    d.type = deviceTypeName(p.deviceType);
    d.api_version = p.apiVersion;
    if (p.apiVersion >= VK_API_VERSION_1_2) {
      VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
      VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
      p2.pNext = &driver;
      vkGetPhysicalDeviceProperties2(devices[i], &p2);
      d.driver = std::string(driver.driverName) + " " + driver.driverInfo;
    }
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &families, props.data());
    for (const auto& f : props)
      d.has_compute = d.has_compute || (f.queueFlags & VK_QUEUE_COMPUTE_BIT);
    infos.push_back(d);
  }
  return {};
}

std::string describeDevices(const std::vector<VulkanDeviceInfo>& infos) {
  std::string s;
  for (const auto& d : infos) {
    s += (s.empty() ? "" : ", ") + std::to_string(d.index) + " '" + d.name + "' (" + d.type + ")";
  }
  return s.empty() ? "none" : s;
}

// Picks a device by index, by name substring, or by type preference when `wanted` is empty.
Expected<int> selectDevice(const std::vector<VulkanDeviceInfo>& infos, const std::string& wanted) {
  if (infos.empty())
    return Status::error(
        "Vulkan: no Vulkan device found (vkEnumeratePhysicalDevices returned none)");
  if (wanted.empty()) {
    int best = -1;
    for (const auto& d : infos) {
      if (!d.has_compute) continue;
      if (best < 0 || typeRank(d.type) < typeRank(infos[best].type)) best = d.index;
    }
    if (best < 0)
      return Status::error("Vulkan: no device with a compute queue among " +
                           describeDevices(infos));
    return best;
  }
  bool numeric = std::all_of(wanted.begin(), wanted.end(),
                             [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
  int index = -1;
  if (numeric) {
    long long v = wanted.size() > 9 ? -1 : std::stoll(wanted);
    if (v < 0 || v >= (long long)infos.size()) {
      return Status::error("Vulkan: device index " + wanted +
                           " out of range; devices: " + describeDevices(infos));
    }
    index = int(v);
  } else {
    for (const auto& d : infos) {
      if (lower(d.name).find(lower(wanted)) != std::string::npos) {
        index = d.index;
        break;
      }
    }
    if (index < 0)
      return Status::error("Vulkan: no device named '" + wanted +
                           "'; devices: " + describeDevices(infos));
  }
  if (!infos[index].has_compute)
    return Status::error("Vulkan: device '" + infos[index].name + "' has no compute queue");
  return index;
}

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

// Everything one bake creates on the device; destroyed in reverse order.
struct Context {
  Instance instance;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties props{};
  VkPhysicalDeviceMemoryProperties memory_props{};
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  VkCommandBuffer command_buffer = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  VkShaderModule shader = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  VkDescriptorSet descriptor_set = VK_NULL_HANDLE;
  std::vector<Buffer> buffers;

  ~Context() {
    if (device) {
      vkDeviceWaitIdle(device);
      for (Buffer& b : buffers) {
        if (b.mapped) vkUnmapMemory(device, b.memory);
        if (b.buffer) vkDestroyBuffer(device, b.buffer, nullptr);
        if (b.memory) vkFreeMemory(device, b.memory, nullptr);
      }
      if (descriptor_pool) vkDestroyDescriptorPool(device, descriptor_pool, nullptr);
      if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
      if (shader) vkDestroyShaderModule(device, shader, nullptr);
      if (pipeline_layout) vkDestroyPipelineLayout(device, pipeline_layout, nullptr);
      if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
      if (fence) vkDestroyFence(device, fence, nullptr);
      if (command_pool) vkDestroyCommandPool(device, command_pool, nullptr);
      vkDestroyDevice(device, nullptr);
    }
  }

  Status createDevice(int index, const std::vector<VkPhysicalDevice>& devices) {
    physical = devices[size_t(index)];
    vkGetPhysicalDeviceProperties(physical, &props);
    // The kernel accounts its loop iterations with subgroupMax (shaders/bake.comp).
    VkPhysicalDeviceSubgroupProperties subgroup{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props2.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(physical, &props2);
    if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
        !(subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT)) {
      return Status::error(
          std::string("Vulkan: device '") + props.deviceName +
          "' lacks subgroup arithmetic in compute shaders, which the bake kernel needs");
    }
    vkGetPhysicalDeviceMemoryProperties(physical, &memory_props);
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> fp(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, fp.data());
    bool found = false;
    for (uint32_t i = 0; i < families && !found; ++i) {
      if (fp[i].queueFlags & VK_QUEUE_COMPUTE_BIT) queue_family = i, found = true;
    }
    if (!found) return Status::error("Vulkan: device has no compute queue");
    float priority = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = queue_family;
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &q;
    RDM_VK_TRY(vkCreateDevice(physical, &info, nullptr, &device));
    vkGetDeviceQueue(device, queue_family, 0, &queue);
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = queue_family;
    RDM_VK_TRY(vkCreateCommandPool(device, &pool, nullptr, &command_pool));
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = command_pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    RDM_VK_TRY(vkAllocateCommandBuffers(device, &alloc, &command_buffer));
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    RDM_VK_TRY(vkCreateFence(device, &fence_info, nullptr, &fence));
    return {};
  }

  // A host-visible, coherent storage buffer (device-local too where the device offers it).
  Expected<Buffer*> createBuffer(VkDeviceSize size, const char* what) {
    size = std::max<VkDeviceSize>(size, 16);
    if (size > props.limits.maxStorageBufferRange) {
      return Status::error(std::string("Vulkan: the ") + what + " buffer needs " +
                           std::to_string(size) +
                           " bytes, more than the device's maxStorageBufferRange " +
                           std::to_string(props.limits.maxStorageBufferRange));
    }
    buffers.emplace_back();
    Buffer& b = buffers.back();
    b.size = size;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    RDM_VK_TRY(vkCreateBuffer(device, &info, nullptr, &b.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, b.buffer, &req);
    const VkMemoryPropertyFlags need =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    int type = -1;
    for (int pass = 0; pass < 2 && type < 0; ++pass) {
      VkMemoryPropertyFlags want = pass == 0 ? (need | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) : need;
      for (uint32_t i = 0; i < memory_props.memoryTypeCount; ++i) {
        if ((req.memoryTypeBits & (1u << i)) &&
            (memory_props.memoryTypes[i].propertyFlags & want) == want) {
          type = int(i);
          break;
        }
      }
    }
    if (type < 0)
      return Status::error("Vulkan: no host-visible coherent memory type for storage buffers");
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = uint32_t(type);
    RDM_VK_TRY(vkAllocateMemory(device, &alloc, nullptr, &b.memory));
    RDM_VK_TRY(vkBindBufferMemory(device, b.buffer, b.memory, 0));
    RDM_VK_TRY(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    return &b;
  }

  Status createPipeline(bool sun, bool emitters) {
    std::vector<VkDescriptorSetLayoutBinding> bindings(gpu::kBindingCount);
    for (int i = 0; i < gpu::kBindingCount; ++i) {
      bindings[size_t(i)] = {uint32_t(i), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                             VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    }
    VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.bindingCount = uint32_t(bindings.size());
    set_info.pBindings = bindings.data();
    RDM_VK_TRY(vkCreateDescriptorSetLayout(device, &set_info, nullptr, &set_layout));
    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::GpuPush)};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout;
    layout_info.pushConstantRangeCount = 1;
    layout_info.pPushConstantRanges = &push;
    RDM_VK_TRY(vkCreatePipelineLayout(device, &layout_info, nullptr, &pipeline_layout));
    VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module.codeSize = spirv::kBakeCompWords * sizeof(uint32_t);
    module.pCode = spirv::kBakeComp;
    RDM_VK_TRY(vkCreateShaderModule(device, &module, nullptr, &shader));
    // The effect set as specialization constants 0 (sun) and 1 (emitters).
    const VkBool32 constants[2] = {sun ? VK_TRUE : VK_FALSE, emitters ? VK_TRUE : VK_FALSE};
    const VkSpecializationMapEntry entries[2] = {{0, 0, sizeof(VkBool32)},
                                                 {1, sizeof(VkBool32), sizeof(VkBool32)}};
    VkSpecializationInfo spec{2, entries, sizeof(constants), constants};
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = shader;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = &spec;
    info.layout = pipeline_layout;
    RDM_VK_TRY(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, uint32_t(gpu::kBindingCount)};
    VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool.maxSets = 1;
    pool.poolSizeCount = 1;
    pool.pPoolSizes = &size;
    RDM_VK_TRY(vkCreateDescriptorPool(device, &pool, nullptr, &descriptor_pool));
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = descriptor_pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &set_layout;
    RDM_VK_TRY(vkAllocateDescriptorSets(device, &alloc, &descriptor_set));
    return {};
  }

  void bind(const std::vector<Buffer*>& by_binding) {
    std::vector<VkDescriptorBufferInfo> infos(by_binding.size());
    std::vector<VkWriteDescriptorSet> writes(by_binding.size());
    for (size_t i = 0; i < by_binding.size(); ++i) {
      infos[i] = {by_binding[i]->buffer, 0, VK_WHOLE_SIZE};
      writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      writes[i].dstSet = descriptor_set;
      writes[i].dstBinding = uint32_t(i);
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(device, uint32_t(writes.size()), writes.data(), 0, nullptr);
  }

  // Records and runs one dispatch (after clearing `clear` when given) and waits for it.
  Status dispatch(const gpu::GpuPush& push, uint32_t invocations, Buffer* clear) {
    RDM_VK_TRY(vkResetCommandBuffer(command_buffer, 0));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    RDM_VK_TRY(vkBeginCommandBuffer(command_buffer, &begin));
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_HOST_WRITE_BIT;
    barrier.dstAccessMask =
        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_HOST_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         1, &barrier, 0, nullptr, 0, nullptr);
    if (clear) {
      vkCmdFillBuffer(command_buffer, clear->buffer, 0, VK_WHOLE_SIZE, 0u);
      barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
      vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0,
                           nullptr);
    }
    vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout, 0, 1,
                            &descriptor_set, 0, nullptr);
    vkCmdPushConstants(command_buffer, pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                       sizeof(push), &push);
    vkCmdDispatch(command_buffer, (invocations + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize, 1,
                  1);
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
    RDM_VK_TRY(vkEndCommandBuffer(command_buffer));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &command_buffer;
    RDM_VK_TRY(vkResetFences(device, 1, &fence));
    RDM_VK_TRY(vkQueueSubmit(queue, 1, &submit, fence));
    RDM_VK_TRY(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
    return {};
  }
};

// A texel job and the group its samples accumulate into: the texel itself, or at level 7
// every texel of the face (the face mean).
struct Job {
  int rdm, face, i, j;
  int group;  // index of the group's first job
  gpu::GpuJob gpu;
};

template <class T>
void upload(Buffer* b, const std::vector<T>& data) {
  if (!data.empty()) std::memcpy(b->mapped, data.data(), data.size() * sizeof(T));
}

}  // namespace

Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices() {
  Instance instance;
  if (Status s = createInstance(instance); !s) return s;
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  if (Status s = enumerateDevices(instance.handle, devices, infos); !s) return s;
  return infos;
}

BackendChoice resolveBakeBackend(BakeBackend requested, const std::string& device) {
  if (requested != BakeBackend::kAuto)
    return {requested, std::string("requested --backend ") + bakeBackendName(requested)};
  auto devices = listVulkanDevices();
  if (!devices)
    return {BakeBackend::kCpu, "auto: no usable Vulkan (" + devices.error() + "), using the CPU"};
  auto index = selectDevice(*devices, device);
  if (!index) return {BakeBackend::kCpu, "auto: " + index.error() + ", using the CPU"};
  const VulkanDeviceInfo& d = (*devices)[size_t(*index)];
  if (d.type == "cpu") {
    return {BakeBackend::kCpu, "auto: the Vulkan device '" + d.name +
                                   "' is a CPU implementation, slower than the CPU baker on the "
                                   "same cores; using the CPU"};
  }
  return {BakeBackend::kVulkan, "auto: Vulkan device '" + d.name + "' (" + d.type + ")"};
}

Expected<BakeResult> bakeRdmsVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                    const std::vector<RdmId>& rdms,
                                    const VulkanBakeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  if (settings.spp < 1) return Status::error("Vulkan bake: spp must be at least 1");
  if (world.size.x > 256 || world.size.y > 256 || world.size.z > 256) {
    return Status::error("Vulkan bake: the grid exceeds 256 slots per axis");
  }

  // --- Device, pipeline ---------------------------------------------------------------
  Context ctx;
  if (Status s = createInstance(ctx.instance); !s) return s;
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  if (Status s = enumerateDevices(ctx.instance.handle, devices, infos); !s) return s;
  auto index = selectDevice(infos, options.device);
  if (!index) return index.status();
  if (Status s = ctx.createDevice(*index, devices); !s) return s;
  BakeResult result;
  BakeReport& report = result.report;
  report.effects = sceneEffects(world);
  const bool sun = report.effects.sun || options.all_effects;
  const bool emit = report.effects.emitters || options.all_effects;
  if (Status s = ctx.createPipeline(sun, emit); !s) return s;

  // --- Scene buffers ------------------------------------------------------------------
  gpu::GpuParams params{};
  const ivec3 extent = world.voxelExtent();
  params.world = glm::ivec4(world.size, extent.x + extent.y + extent.z + 8);
  params.config = glm::uvec4(settings.seed, uint32_t(std::max(0, settings.max_bounces)),
                             uint32_t(world.emitters.emitters.size()), world.sun.present ? 1u : 0u);
  params.sun_direction = glm::vec4(world.sun.direction, world.sun.pdf);
  params.sun_radiance = glm::vec4(world.sun.radiance, world.sun.one_minus_cos_max);
  params.sun_irradiance = glm::vec4(world.sun.irradiance, world.sun.disc_c2);
  params.sky_zenith = glm::vec4(world.sky.zenith, world.emitters.total_luminance);
  params.sky_horizon = glm::vec4(world.sky.horizon, 0.0f);
  params.sky_ground = glm::vec4(world.sky.ground, 0.0f);
  std::vector<gpu::GpuMaterial> materials(256);
  for (size_t p = 0; p < 256; ++p) {
    const Material& m = world.materials[p];
    materials[p].base_metallic = glm::vec4(m.base_color, m.metallic);
    materials[p].f0_alpha = glm::vec4(m.f0, m.alpha);
    materials[p].emission = glm::vec4(m.emission, 0.0f);
    materials[p].flags = glm::uvec4(m.emissive ? 1u : 0u, uint32_t(m.roughness), 0u, 0u);
  }
  std::vector<uint32_t> voxels(world.blocks.size() * 1024, 0u);
  for (size_t b = 0; b < world.blocks.size(); ++b)
    for (size_t v = 0; v < 4096; ++v)
      voxels[b * 1024 + v / 4] |= uint32_t(world.blocks[b].voxels[v]) << (8 * (v % 4));
  std::vector<gpu::GpuEmitter> emitters;
  for (const Emitter& e : world.emitters.emitters)
    emitters.push_back({glm::ivec4(e.voxel, e.face), glm::vec4(e.radiance, 0.0f)});

  const uint32_t spp = uint32_t(settings.spp);
  const uint64_t budget_paths = std::max<uint64_t>(gpu::kWorkgroupSize, options.max_batch_paths);
  const uint64_t batch_paths = std::min<uint64_t>(
      budget_paths, ctx.props.limits.maxStorageBufferRange / sizeof(gpu::GpuPathState));
  const uint32_t max_jobs = uint32_t(std::max<uint64_t>(1, batch_paths / spp));
  const uint32_t loop_budget = std::clamp<uint32_t>(options.loop_budget, 256u, gpu::kMaxLoopBudget);

  Buffer* b_params;
  Buffer *b_slots, *b_voxels, *b_materials, *b_emitters, *b_cdf, *b_jobs, *b_paths, *b_results,
      *b_counters;
  {
    auto check = [](Expected<Buffer*> e, Buffer*& out) -> Status {
      if (!e) return e.status();
      out = *e;
      return {};
    };
    ctx.buffers.reserve(gpu::kBindingCount);
    Status s;
    if (s = check(ctx.createBuffer(sizeof(params), "parameter"), b_params); !s) return s;
    if (s = check(ctx.createBuffer(world.slots.size() * sizeof(int32_t), "slot grid"), b_slots); !s)
      return s;
    if (s = check(ctx.createBuffer(voxels.size() * sizeof(uint32_t), "voxel"), b_voxels); !s)
      return s;
    if (s = check(ctx.createBuffer(materials.size() * sizeof(gpu::GpuMaterial), "material"),
                  b_materials);
        !s)
      return s;
    if (s = check(ctx.createBuffer(emitters.size() * sizeof(gpu::GpuEmitter), "emitter"),
                  b_emitters);
        !s)
      return s;
    if (s = check(ctx.createBuffer(world.emitters.cdf.size() * sizeof(float), "emitter CDF"),
                  b_cdf);
        !s)
      return s;
    if (s = check(
            ctx.createBuffer(
                uint64_t(std::min<uint64_t>(max_jobs, batch_paths)) * sizeof(gpu::GpuJob), "job"),
            b_jobs);
        !s)
      return s;
    if (s = check(ctx.createBuffer(batch_paths * sizeof(gpu::GpuPathState), "path state"), b_paths);
        !s)
      return s;
    if (s = check(ctx.createBuffer(batch_paths * sizeof(glm::vec4), "result"), b_results); !s)
      return s;
    if (s = check(ctx.createBuffer(sizeof(gpu::GpuCounters), "counter"), b_counters); !s) return s;
  }
  std::memcpy(b_params->mapped, &params, sizeof(params));
  upload(b_slots, world.slots);
  upload(b_voxels, voxels);
  upload(b_materials, materials);
  upload(b_emitters, emitters);
  upload(b_cdf, world.emitters.cdf);
  ctx.bind({b_params, b_slots, b_voxels, b_materials, b_emitters, b_cdf, b_jobs, b_paths, b_results,
            b_counters});

  VulkanBakeInfo info;
  info.device = infos[size_t(*index)];
  info.setup_seconds = elapsed();

  // --- Plan: RDM images, skipped faces, texel jobs in (rdm, face, j, i) order -------------
  std::vector<Job> jobs;
  for (const RdmId& id : rdms) {
    RdmData data;
    data.id = id;
    data.image = Image(2 * id.size, 3 * id.size, 4);
    data.stderr_rgb.assign(size_t(data.image.width) * data.image.height * 3, 0.0f);
    data.max_samples = spp;
    const int r = int(result.rdms.size());
    const int S = id.size;
    const ivec3 origin_base = id.slot * 16 + ivec3(8);
    for (int f = 0; f < 6; ++f) {
      data.skipped[size_t(f)] = faceSkipped(world, id.slot, f);
      if (data.skipped[size_t(f)]) {
        ++report.faces_skipped;
        continue;
      }
      ++report.faces_baked;
      const ivec3 origin = origin_base + 8 * shared::faceNormal(f);
      const int group_start = int(jobs.size());
      for (int j = 0; j < S; ++j)
        for (int i = 0; i < S; ++i) {
          Job job{r, f, i, j, id.level == shared::kDiffuseLevel ? group_start : int(jobs.size()),
                  {}};
          job.gpu.data =
              glm::uvec4(slotKey(id.slot), uint32_t(id.level) | uint32_t(f) << 4 | uint32_t(S) << 8,
                         uint32_t(i) | uint32_t(j) << 16, 0u);
          jobs.push_back(job);
          // Depth: the exact integer central ray, as the CPU backend computes it.
          const ivec3 d = shared::texelCentralDirection(i, j, S);
          const ivec3 dir = d.x * shared::faceTangent(f) + d.y * shared::faceBitangent(f) +
                            d.z * shared::faceNormal(f);
          const glm::ivec2 px = shared::rdmTexelPixel(0, 0, S, f, i, j);
          data.image.at(px.x, px.y, 3) = exactCentralDepth(world, origin, dir);
        }
    }
    result.rdms.push_back(std::move(data));
  }
  std::vector<int> jobs_left(result.rdms.size(), 0);
  for (const Job& j : jobs) ++jobs_left[size_t(j.rdm)];
  int rdms_done = 0;
  for (int left : jobs_left) rdms_done += left == 0 ? 1 : 0;

  // --- Batches: jobs [j0, j0 + nj) x samples [s0, s0 + ns) --------------------------------
  SampleEstimator estimator;
  int current_group = -1;
  auto finishGroup = [&](int group) {
    if (group < 0) return;
    const Job& first = jobs[size_t(group)];
    RdmData& rdm = result.rdms[size_t(first.rdm)];
    const int S = rdm.id.size;
    const size_t count = rdm.id.level == shared::kDiffuseLevel ? size_t(S) * S : 1;
    const glm::dvec3 mean = estimator.mean(), err = estimator.stderror();
    for (size_t n = 0; n < count; ++n) {
      const Job& job = jobs[size_t(group) + n];
      const glm::ivec2 px = shared::rdmTexelPixel(0, 0, S, job.face, job.i, job.j);
      for (int c = 0; c < 3; ++c) {
        rdm.image.at(px.x, px.y, c) = float(mean[c]);
        rdm.stderr_rgb[(size_t(px.y) * rdm.image.width + px.x) * 3 + c] = float(err[c]);
      }
    }
    estimator = SampleEstimator();
  };

  uint64_t rays = 0;
  bool cancelled = false;
  std::vector<glm::vec4> batch_results;
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done, int(result.rdms.size()), rays, elapsed()});
  };
  size_t j0 = 0;
  uint32_t s0 = 0;
  while (j0 < jobs.size() && !cancelled) {
    const uint32_t nj = uint32_t(std::min<size_t>(max_jobs, jobs.size() - j0));
    const uint32_t ns =
        spp <= batch_paths ? spp : uint32_t(std::min<uint64_t>(batch_paths, spp - s0));
    const uint32_t paths = nj * ns;
    for (uint32_t n = 0; n < nj; ++n)
      static_cast<gpu::GpuJob*>(b_jobs->mapped)[n] = jobs[j0 + n].gpu;
    gpu::GpuPush push{glm::uvec4(nj, ns, s0, loop_budget)};
    ++info.batches;
    uint64_t dispatches = 0;
    for (bool first = true;; first = false) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      std::memset(b_counters->mapped, 0, sizeof(gpu::GpuCounters));
      if (Status s = ctx.dispatch(push, paths, first ? b_paths : nullptr); !s) return s;
      ++dispatches;
      const gpu::GpuCounters counters = *static_cast<const gpu::GpuCounters*>(b_counters->mapped);
      rays += uint64_t(counters.values.y) + (uint64_t(counters.values.z) << 32);
      progress();
      if (counters.values.x == 0) break;
    }
    info.dispatches += dispatches;
    info.max_dispatches_per_batch = std::max(info.max_dispatches_per_batch, dispatches);
    if (cancelled) break;
    // Accumulate in job, then sample order (the CPU's order).
    const glm::vec4* out = static_cast<const glm::vec4*>(b_results->mapped);
    for (uint32_t n = 0; n < nj; ++n) {
      const Job& job = jobs[j0 + n];
      if (job.group != current_group) {
        finishGroup(current_group);
        current_group = job.group;
      }
      for (uint32_t s = 0; s < ns; ++s) {
        const glm::vec4 v = out[size_t(n) * ns + s];
        estimator.add(vec3(v), v.w);
      }
    }
    s0 += ns;
    if (s0 >= spp) {
      for (uint32_t n = 0; n < nj; ++n) {
        if (--jobs_left[size_t(jobs[j0 + n].rdm)] == 0) ++rdms_done;
      }
      s0 = 0;
      j0 += nj;
    }
    progress();
  }
  if (!cancelled) finishGroup(current_group);

  report.rdms = int(result.rdms.size());
  report.rays = rays;
  report.cancelled = cancelled;
  report.seconds = elapsed();
  summariseBake(result.rdms, report);
  if (options.info) *options.info = info;
  return result;
}

#endif  // RDM_HAVE_VULKAN

}  // namespace rdm
