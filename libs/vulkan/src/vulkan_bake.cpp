// Vulkan compute backend of the RDM bake (include/rdm/vulkan_bake.h, docs/vulkan.md): the API,
// the backend choice and VulkanBaker, which keeps the device and its pipelines across bakes.
// One bake (plan, batches, the host-side estimators) is vulkan_bake_batches.cpp; the kernel
// (shaders/bake.comp) traces one path per invocation and writes (radiance, sample weight).
#include "rdm/vulkan/vulkan_bake.h"

#include <chrono>
#include <mutex>

#if RDM_HAVE_VULKAN
#include <vulkan/vulkan.h>

#include "vulkan_context.h"
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

namespace {

// What the Vulkan bake refuses whatever the device.
// The kernel packs a slot's coordinates into 8 bits each (rdm_gpu_layout.h).
Status checkGrid(const VoxelWorld& world) {
  if (world.size.x > 256 || world.size.y > 256 || world.size.z > 256) {
    return Status::error("Vulkan bake: the grid exceeds 256 slots per axis");
  }
  return {};
}

Status checkBakeArguments(const VoxelWorld& world, const BakeSettings& settings) {
  if (settings.spp < 1) return Status::error("Vulkan bake: spp must be at least 1");
  return checkGrid(world);
}

}  // namespace

BackendChoice resolveBakeBackend(BakeBackend requested, const std::string& device,
                                 const Scene& scene) {
  if (requested == BakeBackend::kAuto && usesGlass(scene))
    return {BakeBackend::kCpu, "auto: the scene has glass, which only the CPU path traces"};
  return resolveBakeBackend(requested, device);
}

#if !RDM_HAVE_VULKAN

bool vulkanBackendBuilt() {
  return false;
}
Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices() {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
struct VulkanBaker::Impl {
  VulkanDeviceInfo device;
};
Expected<std::unique_ptr<VulkanBaker>> VulkanBaker::create(const std::string&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
const VulkanDeviceInfo& VulkanBaker::device() const {
  return impl_->device;
}
Expected<BakeResult> VulkanBaker::bake(const VoxelWorld&, const BakeSettings&,
                                       const std::vector<RdmId>&, const VulkanBakeOptions&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
Status VulkanBaker::traceFaceLight(const VoxelWorld&, const BakeSettings&, int,
                                   std::vector<FaceLightSlot>&, const FaceLightTraceHooks&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
Expected<Image> VulkanBaker::render(const Scene&, const VoxelWorld&, const RenderOptions&,
                                    RenderReport*) {
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

using namespace vkbake;

namespace {

VulkanInstanceOptions bakeInstanceOptions() {
  VulkanInstanceOptions options;
  options.application = "rdm-bake";
  return options;
}

}  // namespace

Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices() {
  auto instance = VulkanInstance::create(bakeInstanceOptions());
  if (!instance) return instance.status();
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  if (Status s = enumerateVulkanDevices(instance->handle(), devices, infos); !s) return s;
  return infos;
}

BackendChoice resolveBakeBackend(BakeBackend requested, const std::string& device) {
  if (requested != BakeBackend::kAuto)
    return {requested, std::string("requested --backend ") + bakeBackendName(requested)};
  auto devices = listVulkanDevices();
  if (!devices)
    return {BakeBackend::kCpu, "auto: no usable Vulkan (" + devices.error() + "), using the CPU"};
  auto index = selectVulkanDevice(*devices, device, QueueNeed::kCompute);
  if (!index) return {BakeBackend::kCpu, "auto: " + index.error() + ", using the CPU"};
  const VulkanDeviceInfo& d = (*devices)[size_t(*index)];
  if (d.type == "cpu") {
    return {BakeBackend::kCpu, "auto: the Vulkan device '" + d.name +
                                   "' is a CPU implementation, slower than the CPU baker on the "
                                   "same cores; using the CPU"};
  }
  return {BakeBackend::kVulkan, "auto: Vulkan device '" + d.name + "' (" + d.type + ")"};
}

struct VulkanBaker::Impl {
  Context ctx;
  VulkanDeviceInfo device;
  std::mutex busy;  // one bake or face light on the device's queue and descriptor sets
};

Expected<std::unique_ptr<VulkanBaker>> VulkanBaker::create(const std::string& device) {
  auto impl = std::make_unique<Impl>();
  Context& ctx = impl->ctx;
  auto instance = VulkanInstance::create(bakeInstanceOptions());
  if (!instance) return instance.status();
  ctx.instance = std::move(*instance);
  auto choice = chooseVulkanDevice(ctx.instance.handle(), device, QueueNeed::kCompute);
  if (!choice) return choice.status();
  if (Status s = ctx.createDevice(*choice); !s) return s;
  if (Status s = ctx.createLayout(); !s) return s;
  impl->device = choice->info;
  return std::unique_ptr<VulkanBaker>(new VulkanBaker(std::move(impl)));
}

const VulkanDeviceInfo& VulkanBaker::device() const {
  return impl_->device;
}

Expected<BakeResult> VulkanBaker::bake(const VoxelWorld& world, const BakeSettings& settings,
                                       const std::vector<RdmId>& rdms,
                                       const VulkanBakeOptions& options) {
  if (Status s = checkBakeArguments(world, settings); !s) return s;
  std::lock_guard<std::mutex> lock(impl_->busy);
  return bakeOnContext(impl_->ctx, impl_->device, world, settings, rdms, options);
}

Status VulkanBaker::traceFaceLight(const VoxelWorld& world, const BakeSettings& settings, int spp,
                                   std::vector<FaceLightSlot>& slots,
                                   const FaceLightTraceHooks& hooks) {
  if (Status s = checkGrid(world); !s) return s;
  std::lock_guard<std::mutex> lock(impl_->busy);
  return traceFaceLightOnContext(impl_->ctx, world, settings, spp, slots, hooks);
}

Expected<Image> VulkanBaker::render(const Scene& scene, const VoxelWorld& world,
                                    const RenderOptions& options, RenderReport* report) {
  if (Status s = checkRenderOptions(scene, options); !s) return s;
  if (Status s = checkGrid(world); !s) return s;
  std::lock_guard<std::mutex> lock(impl_->busy);
  return renderOnContext(impl_->ctx, scene, world, options, report);
}

#endif  // RDM_HAVE_VULKAN

VulkanBaker::VulkanBaker(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanBaker::~VulkanBaker() = default;

Expected<BakeResult> bakeRdmsVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                    const std::vector<RdmId>& rdms,
                                    const VulkanBakeOptions& options) {
  if (Status s = checkBakeArguments(world, settings); !s) return s;
  const auto start = std::chrono::steady_clock::now();
  auto baker = VulkanBaker::create(options.device);
  if (!baker) return baker.status();
  const double created =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  auto result = (*baker)->bake(world, settings, rdms, options);
  // The device and pipeline creation belong to this bake's setup and time.
  if (result) result->report.seconds += created;
  if (result && options.info) options.info->setup_seconds += created;
  return result;
}

}  // namespace rdm
