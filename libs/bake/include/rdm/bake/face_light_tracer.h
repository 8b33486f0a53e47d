// Where a face light's paths are traced (docs/spec.md section 3.2): on the CPU's cores
// (CpuFaceLightTracer) or on a device (the Vulkan backend's VulkanFaceLightTracer). Every
// tracer traces the same paths, bakeFaceLightSlot's keys, origins and estimator; the CPU's
// give its bits, a device's agree within docs/spec.md section 5's cross-backend tolerances.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct FaceLightSlot;

struct FaceLightTraceHooks {
  // Checked between slots (CPU: also every 1024 paths; a device: between dispatches). Once
  // true, trace returns early with some slots incomplete.
  const std::atomic<bool>* stop = nullptr;
  // A slot's light is complete: its exposed faces and the rays its paths traced. May be
  // called from any thread, concurrently.
  std::function<void(size_t faces, uint64_t rays)> on_slot_done;
  // Called on the calling thread about every 20 ms while slots trace, and once after.
  std::function<void()> on_tick;
};

class FaceLightTracer {
 public:
  virtual ~FaceLightTracer() = default;
  // Fills slots[i].light for every slot from its `faces` (exposedFaces order), spp >= 1
  // paths each, with `settings`' bounces and seed. An error only for a device failure.
  [[nodiscard]] virtual Status trace(const VoxelWorld& world, const BakeSettings& settings, int spp,
                                     std::vector<FaceLightSlot>& slots,
                                     const FaceLightTraceHooks& hooks) = 0;
};

// On the CPU, in parallel over slots (`threads`, 0: all cores); never fails, and the bits do
// not depend on the thread count.
class CpuFaceLightTracer final : public FaceLightTracer {
 public:
  explicit CpuFaceLightTracer(int threads = 0) : threads_(threads) {}
  [[nodiscard]] Status trace(const VoxelWorld& world, const BakeSettings& settings, int spp,
                             std::vector<FaceLightSlot>& slots,
                             const FaceLightTraceHooks& hooks) override;

 private:
  int threads_;
};

}  // namespace rdm
