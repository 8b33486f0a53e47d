// The RDM bake on Vulkan compute : the same RdmData as bakeRdms (RGB + Z
// image, per-texel standard errors), from the kernels in shaders/ embedded as SPIR-V.
// Results agree with the CPU within docs/spec.md section 5's cross-backend tolerances and are
// bit-identical run to run on the same device whatever the batch and dispatch split.
// docs/vulkan.md describes the design, the loop-limit handling and measured throughput.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/face_light_tracer.h"
#include "rdm/bake/render.h"
#include "rdm/base/status.h"

namespace rdm {

// True when the build includes the Vulkan backend (CMake option RDM_VULKAN).
bool vulkanBackendBuilt();

struct VulkanDeviceInfo {
  int index = 0;       // position in vkEnumeratePhysicalDevices
  std::string name;    // VkPhysicalDeviceProperties::deviceName
  std::string type;    // "discrete-gpu", "integrated-gpu", "virtual-gpu", "cpu", "other"
  std::string driver;  // driver name and info, when the driver reports them
  uint32_t api_version = 0;
  bool has_compute = false;   // a queue family with compute
  bool has_graphics = false;  // a queue family with graphics
};

// Every Vulkan physical device; an error Status (never a crash) when the loader, the
// driver or the instance is missing.
Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices();

// Statistics of one Vulkan bake, for reports and tests.
struct VulkanBakeInfo {
  VulkanDeviceInfo device;
  uint64_t batches = 0;
  uint64_t dispatches = 0;
  uint64_t max_dispatches_per_batch = 0;  // > 1 when some path was suspended and resumed
  uint64_t prefilter_dispatches = 0;      // of the prefilter pass (prefiltered estimator)
  uint64_t texels_prefiltered = 0;        // rough-level texels the prefilter pass derived
  double prefilter_seconds = 0.0;         // in the prefilter pass: upload, dispatch, read-back
  double max_dispatch_seconds = 0.0;      // the longest submission of the bake kernel
  uint64_t min_loop_budget = 0;           // the smallest loop budget a dispatch ran with
  double setup_seconds = 0.0;             // instance, device, pipeline, scene upload
};

struct VulkanBakeOptions {
  // Device by index ("0") or by case-insensitive name substring ("llvmpipe"); empty: the
  // first discrete GPU, else integrated, virtual, then CPU device.
  std::string device;
  // Paths (texel samples) per batch; a batch is re-dispatched until every path finished.
  uint32_t max_batch_paths = 1u << 18;
  // Loop iterations an invocation may run per dispatch before it saves its path and stops
  // (docs/spec.md section 9: lavapipe cuts loops at 65,535 back-edges); clamped to [256, 60000].
  uint32_t loop_budget = 60000;
  // Wall seconds one submission of the bake kernel should take at most (docs/vulkan.md,
  // "Dispatch budget"): dispatches adapt their loop budget (from 4096 up to loop_budget) and
  // their batch to it; <= 0 runs every dispatch at loop_budget and max_batch_paths.
  double max_dispatch_seconds = 0.5;
  // Rough-level texels queued for the prefilter pass before it runs (it also runs after
  // each batch); 32 bytes of device memory each; one dispatch of at most that many
  // invocations plus one face's.
  uint32_t max_prefilter_texels = 1u << 20;
  bool all_effects = false;  // sun and emitter code compiled in whatever the scene holds
  // As BakeOptions: > 0 samples each texel (map texel, level-7 face) in doubling rounds until
  // its relative standard error is below this, at most spp * max_spp_factor samples.
  double target_error = 0.0;
  int max_spp_factor = 16;
  // Fill RdmData full_set / first_set / smooth_vertex as the CPU bake does with
  // BakeOptions::record_slot_sets (docs/spec.md section 8): the slots the kernel's own walks
  // entered, so an `exact` rebake on this device equals a full bake on it bit for bit.
  bool record_slot_sets = false;
  std::function<void(const BakeProgress&)> on_progress;  // between dispatches
  // As BakeOptions::on_rdm_done: called on the calling thread once per RDM as soon as its
  // texels (and, when recording, its slot sets) are complete; they are freed when it
  // returns, so the bake holds the RDMs whose jobs are in flight, not all of them (an RDM's
  // texels are allocated when its first job, or its slot's first map job, is dispatched).
  std::function<void(const RdmData&)> on_rdm_done;
  const std::atomic<bool>* cancel = nullptr;  // honoured between dispatches
  VulkanBakeInfo* info = nullptr;             // filled when given
};

// A Vulkan device with its bake pipelines, kept across bakes (a daemon creates it once: the
// instance, the device and the compiled pipelines are the costly part of a small bake).
// Thread-safe: bake() and traceFaceLight() take the device in turn.
class VulkanBaker {
 public:
  // `device`: as VulkanBakeOptions::device.
  static Expected<std::unique_ptr<VulkanBaker>> create(const std::string& device);
  ~VulkanBaker();
  VulkanBaker(const VulkanBaker&) = delete;
  VulkanBaker& operator=(const VulkanBaker&) = delete;

  const VulkanDeviceInfo& device() const;
  // As bakeRdmsVulkan, on this baker's device (options.device is ignored).
  Expected<BakeResult> bake(const VoxelWorld& world, const BakeSettings& settings,
                            const std::vector<RdmId>& rdms, const VulkanBakeOptions& options);
  // The face light's paths of `slots` (FaceLightTracer::trace's contract) on this device:
  // the CPU's paths, one kernel job per face (docs/vulkan.md, "Face light").
  Status traceFaceLight(const VoxelWorld& world, const BakeSettings& settings, int spp,
                        std::vector<FaceLightSlot>& slots, const FaceLightTraceHooks& hooks);
  // renderReference on this device (its contract, paths and keys; options.threads unused):
  // one kernel job per pixel, the same image within the kernel's float differences
  // (docs/vulkan.md, "Reference renders").
  Expected<Image> render(const Scene& scene, const VoxelWorld& world, const RenderOptions& options,
                         RenderReport* report = nullptr);

 private:
  struct Impl;
  explicit VulkanBaker(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The face light traced on a VulkanBaker's device (bakeFaceLightOn, updateFaceLightOn).
class VulkanFaceLightTracer final : public FaceLightTracer {
 public:
  explicit VulkanFaceLightTracer(VulkanBaker& baker) : baker_(baker) {}
  [[nodiscard]] Status trace(const VoxelWorld& world, const BakeSettings& settings, int spp,
                             std::vector<FaceLightSlot>& slots,
                             const FaceLightTraceHooks& hooks) override {
    return baker_.traceFaceLight(world, settings, spp, slots, hooks);
  }

 private:
  VulkanBaker& baker_;
};

// Bakes `rdms` (canonical order) on Vulkan: VulkanBaker::create, then bake.
Expected<BakeResult> bakeRdmsVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                    const std::vector<RdmId>& rdms,
                                    const VulkanBakeOptions& options);
Expected<BakeResult> bakeSceneVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                     const VulkanBakeOptions& options);

enum class BakeBackend { kCpu, kVulkan, kAuto };
Expected<BakeBackend> parseBakeBackend(const std::string& text);  // "cpu", "vulkan", "auto"
const char* bakeBackendName(BakeBackend backend);

struct BackendChoice {
  BakeBackend backend = BakeBackend::kCpu;  // kCpu or kVulkan
  std::string reason;
};
// `auto`: Vulkan when the selected (or first-choice) device is a GPU, the CPU backend when
// the only Vulkan device is a CPU implementation such as lavapipe (slower than the CPU
// baker on the same cores, docs/vulkan.md) or when no Vulkan device exists. `cpu` and
// `vulkan` are returned as given.
BackendChoice resolveBakeBackend(BakeBackend requested, const std::string& device);
// As above for `scene`: `auto` takes the CPU for a scene with an effect only the CPU simulates
// (glass, usesGlass).
BackendChoice resolveBakeBackend(BakeBackend requested, const std::string& device,
                                 const Scene& scene);

}  // namespace rdm
