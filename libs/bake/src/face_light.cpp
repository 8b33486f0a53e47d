#include "rdm/bake/face_light.h"

#include <algorithm>
#include <atomic>
#include <tuple>

#include "rdm/bake/bake.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/bake/shard.h"
#include "rdm/base/parallel.h"
#include "rdm/transport/sobol.h"

namespace rdm {
namespace {

using SlotFn = void (*)(const VoxelWorld&, const BakeSettings&, int spp, FaceLightSlot&, PathStats&,
                        const std::atomic<bool>* stop);

template <bool kSun, bool kEmitters>
void bakeSlot(const VoxelWorld& world, const BakeSettings& settings, int spp, FaceLightSlot& out,
              PathStats& stats, const std::atomic<bool>* stop) {
  const uint32_t slot_key = slotKey(out.slot);
  const glm::ivec3 base = out.slot * shared::kBlockSize;
  const float local_sum = kEmitters ? detail::faceLightLocalSum(world, out.slot) : 0.0f;
  out.light.resize(out.faces.size());
  for (size_t i = 0; i < out.faces.size(); ++i) {
    if (stop && stop->load(std::memory_order_relaxed)) return;  // also every 1024 paths below
    const int voxel_index = int(out.faces[i]) / shared::kFaceCount;
    const int face = int(out.faces[i]) % shared::kFaceCount;
    const glm::ivec3 voxel =
        base + glm::ivec3(voxel_index & 15, (voxel_index >> 4) & 15, voxel_index >> 8);
    const shared::ShFrame frame = shared::faceFrameOf(face);
    const uint32_t seed_key =
        shared::pathKey(settings.seed, slot_key, shared::kFaceLightLevel, out.faces[i], 0u);
    glm::dvec3 sum(0.0);
    for (int s = 0; s < spp; ++s) {
      if ((s & 1023) == 1023 && stop && stop->load(std::memory_order_relaxed)) return;
      const uint32_t key = shared::pathKey(settings.seed, slot_key, shared::kFaceLightLevel,
                                           out.faces[i], uint32_t(s));
      const Point2 d = owenSobol2(uint32_t(s), seed_key);
      const shared::OriginDraw o = shared::originCosineDraw(frame, d.u0, d.u1);
      if (!o.traced) continue;
      const glm::vec3 p = shared::faceLightOrigin(
          voxel, face, shared::randomUniform(key, 0, shared::kDimFacePoint0),
          shared::randomUniform(key, 0, shared::kDimFacePoint1));
      if constexpr (kEmitters)
        sum += glm::dvec3(
            detail::sampleEmittersAtFace(world, out.slot, local_sum, frame.n, p, key, stats));
      const PathStart start(PathOrigin::kFaceLight,
                            shared::faceLightDirectionPdf(glm::dot(frame.n, o.dir)), out.slot,
                            local_sum);
      sum += glm::dvec3(
          tracePath<kSun, kEmitters>(world, settings.max_bounces, p, o.dir, key, start, stats));
    }
    out.light[i] = glm::vec3(sum / double(spp));
  }
}

// The kernel for the world's lights. Only the lights decide it: sceneEffects would scan every
// voxel of the world, once per slot.
SlotFn selectSlotKernel(const VoxelWorld& world) {
  const bool sun = world.sun.present, emitters = !world.emitters.empty();
  if (sun && emitters) return bakeSlot<true, true>;
  if (sun) return bakeSlot<true, false>;
  if (emitters) return bakeSlot<false, true>;
  return bakeSlot<false, false>;
}

// This shard's non-empty slots, (i, j, k) lexicographic, without faces yet.
FaceLight shardSlots(const VoxelWorld& world, const Scene& scene, const FaceLightOptions& options) {
  RDM_CHECK(options.shard_count >= 1 && options.shard_index >= 0 &&
            options.shard_index < options.shard_count);
  FaceLight light;
  light.scene_digest = faceLightSceneDigest(scene);
  light.spp = uint32_t(options.spp);
  int non_empty = 0;
  for (int i = 0; i < world.size.x; ++i)
    for (int j = 0; j < world.size.y; ++j)
      for (int k = 0; k < world.size.z; ++k) {
        if (world.blockAt({i, j, k}) < 0) continue;
        if (non_empty++ % options.shard_count == options.shard_index)
          light.slots.push_back({{i, j, k}, {}, {}});
      }
  return light;
}

}  // namespace

size_t FaceLight::faceCount() const {
  size_t n = 0;
  for (const FaceLightSlot& s : slots) n += s.faces.size();
  return n;
}

std::vector<uint32_t> exposedFaces(const VoxelWorld& world, const glm::ivec3& slot) {
  std::vector<uint32_t> faces;
  const int32_t block = world.blockAt(slot);
  if (block < 0) return faces;
  const OrientedBlock& b = world.blocks[size_t(block)];
  const glm::ivec3 base = slot * shared::kBlockSize;
  for (int index = 0; index < shared::kBlockVoxelCount; ++index) {
    if (b.voxels[size_t(index)] == 0) continue;
    const glm::ivec3 local(index & 15, (index >> 4) & 15, index >> 8);
    for (int f = 0; f < shared::kFaceCount; ++f) {
      if (world.voxelAt(base + local + shared::faceNormal(f)) == 0)
        faces.push_back(shared::faceLightTexel(index, f));
    }
  }
  return faces;
}

uint64_t exposedFaceCount(const VoxelWorld& world) {
  uint64_t count = 0;
  for (int k = 0; k < world.size.z; ++k)
    for (int j = 0; j < world.size.y; ++j)
      for (int i = 0; i < world.size.x; ++i) count += exposedFaces(world, {i, j, k}).size();
  return count;
}

std::string faceLightSceneDigest(const Scene& scene) {
  Scene content = scene;
  content.bake = BakeSettings();
  content.face_light_spp = 0;
  content.cameras.clear();
  return sceneDigest(content);
}

Status CpuFaceLightTracer::trace(const VoxelWorld& world, const BakeSettings& settings, int spp,
                                 std::vector<FaceLightSlot>& slots,
                                 const FaceLightTraceHooks& hooks) {
  RDM_CHECK(slots.empty() || spp >= 1);
  ParallelOptions parallel;
  parallel.threads = threads_;
  parallel.on_tick = hooks.on_tick;
  const SlotFn kernel = selectSlotKernel(world);
  auto stopped = [&] { return hooks.stop && hooks.stop->load(std::memory_order_relaxed); };
  parallelFor(slots.size(), parallel, [&](size_t i) {
    if (stopped()) return false;
    PathStats stats;
    kernel(world, settings, spp, slots[i], stats, hooks.stop);
    if (hooks.on_slot_done && !stopped()) hooks.on_slot_done(slots[i].faces.size(), stats.rays);
    return true;
  });
  return {};
}

Expected<FaceLight> bakeFaceLightOn(FaceLightTracer& tracer, const VoxelWorld& world,
                                    const Scene& scene, const FaceLightOptions& options,
                                    PathStats* stats) {
  FaceLight light = shardSlots(world, scene, options);
  ParallelOptions parallel;
  parallel.threads = options.threads;
  // Every slot's exposed faces first: the work list of its kernel and the progress total.
  parallelFor(light.slots.size(), parallel, [&](size_t i) {
    light.slots[i].faces = exposedFaces(world, light.slots[i].slot);
    return true;
  });
  RDM_CHECK(light.slots.empty() || options.spp >= 1);
  const size_t faces_total = light.faceCount();
  std::atomic<size_t> slots_done{0}, faces_done{0};
  std::atomic<uint64_t> rays{0};
  auto stopped = [&] { return options.stop && options.stop->load(std::memory_order_relaxed); };
  auto report = [&] {
    options.on_progress(
        {slots_done.load(), light.slots.size(), faces_done.load(), faces_total, rays.load()});
  };
  FaceLightTraceHooks hooks;
  hooks.stop = options.stop;
  hooks.on_slot_done = [&](size_t faces, uint64_t slot_rays) {
    rays += slot_rays;
    faces_done += faces;
    ++slots_done;
  };
  if (options.on_progress) {
    report();  // before any work
    hooks.on_tick = [&] {
      if (!stopped()) report();
    };
  }
  const BakeSettings& settings = options.settings ? *options.settings : scene.bake;
  if (Status s = tracer.trace(world, settings, options.spp, light.slots, hooks); !s) return s;
  if (stats) stats->rays += rays.load();
  return light;
}

FaceLight bakeFaceLight(const VoxelWorld& world, const Scene& scene,
                        const FaceLightOptions& options, PathStats* stats) {
  CpuFaceLightTracer tracer(options.threads);
  auto light = bakeFaceLightOn(tracer, world, scene, options, stats);
  RDM_CHECK(light.ok() && "the CPU tracer never fails");
  return std::move(*light);
}

bool slotOrderLess(const glm::ivec3& a, const glm::ivec3& b) {
  return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

Expected<FaceLight> mergeFaceLights(std::vector<FaceLight> shards, const std::vector<RdmId>& rdms) {
  if (shards.empty()) return Status::invalid(kFaceLightFile, "no shard face lights to merge");
  std::vector<glm::ivec3> want;
  for (const RdmId& id : rdms) want.push_back(id.slot);
  std::sort(want.begin(), want.end(), slotOrderLess);
  want.erase(std::unique(want.begin(), want.end()), want.end());
  FaceLight out;
  out.scene_digest = shards.front().scene_digest, out.spp = shards.front().spp;
  for (FaceLight& s : shards) {
    if (s.scene_digest != out.scene_digest || s.spp != out.spp)
      return Status::invalid(kFaceLightFile,
                             "the shards' face lights were baked from different scenes or spp");
    for (FaceLightSlot& slot : s.slots) out.slots.push_back(std::move(slot));
  }
  std::sort(out.slots.begin(), out.slots.end(),
            [&](const FaceLightSlot& a, const FaceLightSlot& b) {
              return slotOrderLess(a.slot, b.slot);
            });
  std::vector<glm::ivec3> have;
  for (const FaceLightSlot& s : out.slots) have.push_back(s.slot);
  if (have != want)
    return Status::invalid(kFaceLightFile, "the shards' face lights cover " +
                                               std::to_string(have.size()) +
                                               " slots (with repeats), the scene has " +
                                               std::to_string(want.size()) + " non-empty slots");
  return out;
}

}  // namespace rdm
