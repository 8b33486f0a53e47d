// The face light on the bake kernel (docs/spec.md section 3.2, docs/vulkan.md): one texel job
// per exposed voxel face (kFaceLightLevel, rdm_gpu_layout.h), spp samples each, in slot then
// face order; the host sums each face's samples in sample order in double and divides by
// spp, as the CPU's kernel does, so the two agree within the kernel's float differences.
#if RDM_HAVE_VULKAN

#include <algorithm>

#include "rdm/bake/bake_stats.h"
#include "rdm/bake/face_light.h"
#include "rdm/base/check.h"
#include "rdm/trace/integrator.h"
#include "vulkan_context.h"
#include "vulkan_kernel_run.h"

namespace rdm::vkbake {
namespace {

// The (slot, face) of the next face-light job, in slot then face order.
struct FaceCursor {
  size_t slot = 0, face = 0;
};

// Sums each face's samples and hands finished slots out.
class FaceLightSums {
 public:
  FaceLightSums(std::vector<FaceLightSlot>& slots, int spp, const FaceLightTraceHooks& hooks)
      : slots_(slots), spp_(uint32_t(spp)), hooks_(hooks), sums_(slots.size()) {}

  // Samples [s0, s0 + count) of face `c.face` of slot `c.slot`.
  void add(const FaceCursor& c, uint32_t s0, const glm::vec4* values, uint32_t count) {
    std::vector<glm::dvec3>& sums = sums_[c.slot];
    if (sums.empty()) sums.assign(slots_[c.slot].faces.size(), glm::dvec3(0.0));
    for (uint32_t s = 0; s < count; ++s) {
      checkPathResult(values[s]);
      sums[c.face] += glm::dvec3(glm::vec3(values[s]));
    }
    if (s0 + count == spp_ && c.face + 1 == sums.size()) finish(c.slot);
  }

  // A slot without exposed faces is complete as it is.
  void finishEmpty(size_t slot) { finish(slot); }
  void addRays(uint64_t rays) { unreported_rays_ += rays; }

 private:
  void finish(size_t slot) {
    FaceLightSlot& out = slots_[slot];
    std::vector<glm::dvec3>& sums = sums_[slot];
    out.light.resize(out.faces.size());
    for (size_t f = 0; f < out.faces.size(); ++f) out.light[f] = glm::vec3(sums[f] / double(spp_));
    std::vector<glm::dvec3>().swap(sums);
    if (hooks_.on_slot_done) hooks_.on_slot_done(out.faces.size(), unreported_rays_);
    unreported_rays_ = 0;
  }

  std::vector<FaceLightSlot>& slots_;
  const uint32_t spp_;
  const FaceLightTraceHooks& hooks_;
  std::vector<std::vector<glm::dvec3>> sums_;  // per slot in flight, per face
  uint64_t unreported_rays_ = 0;
};

// Moves `c` past slots without faces to the next job; false at the end.
bool skipEmpty(FaceCursor& c, const std::vector<FaceLightSlot>& slots) {
  while (c.slot < slots.size() && c.face >= slots[c.slot].faces.size()) ++c.slot, c.face = 0;
  return c.slot < slots.size();
}

}  // namespace

Status traceFaceLightOnContext(Context& ctx, const VoxelWorld& world, const BakeSettings& settings,
                               int spp, std::vector<FaceLightSlot>& slots,
                               const FaceLightTraceHooks& hooks) {
  RDM_CHECK(slots.empty() || spp >= 1);
  auto tick = [&] {
    if (hooks.on_tick) hooks.on_tick();
  };
  FaceLightSums sums(slots, spp, hooks);
  size_t faces = 0;
  for (size_t i = 0; i < slots.size(); ++i) {
    faces += slots[i].faces.size();
    if (slots[i].faces.empty()) sums.finishEmpty(i);
  }
  if (faces == 0) {
    tick();
    return {};
  }
  KernelConfig config;
  config.sun = world.sun.present, config.emitters = !world.emitters.empty();
  config.spp = uint32_t(spp);
  auto created = KernelRun::create(ctx, world, settings, config);
  if (!created) return created.status();
  KernelRun& kernel = **created;
  // Each slot's local emitter choice (docs/spec.md section 3.2), the CPU's own value: the
  // kernel reads it from the job (rdm_gpu_layout.h).
  std::vector<float> local_sums(slots.size(), 0.0f);
  if (config.emitters)
    for (size_t i = 0; i < slots.size(); ++i)
      local_sums[i] = detail::faceLightLocalSum(world, slots[i].slot);
  FaceCursor cursor;
  uint32_t s0 = 0;
  while (skipEmpty(cursor, slots)) {
    const uint32_t ns = kernel.samplesFrom(s0);
    // The batch: up to maxJobs() faces from the cursor, across slots.
    std::vector<FaceCursor> batch;
    for (FaceCursor c = cursor; batch.size() < kernel.maxJobs() && skipEmpty(c, slots); ++c.face) {
      const FaceLightSlot& slot = slots[c.slot];
      const uint32_t texel = slot.faces[c.face];
      const uint32_t face = texel % uint32_t(shared::kFaceCount);
      kernel.jobs()[batch.size()].data =
          glm::uvec4(slotKey(slot.slot), shared::kFaceLightLevel | face << 4, texel,
                     glm::floatBitsToUint(local_sums[c.slot]));
      batch.push_back(c);
    }
    const uint64_t rays_before = kernel.rays();
    auto ran = kernel.runBatch(uint32_t(batch.size()), ns, s0, hooks.stop, tick);
    if (!ran) return ran.status();
    if (!*ran) return {};  // stopped: slots left incomplete
    sums.addRays(kernel.rays() - rays_before);
    for (size_t n = 0; n < batch.size(); ++n) sums.add(batch[n], s0, kernel.results() + n * ns, ns);
    s0 += ns;
    if (s0 >= uint32_t(spp)) {
      s0 = 0;
      cursor = batch.back();
      ++cursor.face;
    }
  }
  tick();
  return {};
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
