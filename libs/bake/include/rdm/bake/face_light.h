// Face light (docs/spec.md section 3.2): the indirect diffuse light of every exposed voxel
// face, path traced from the face itself, so light under pieces, in corners and beside lamps
// is right where the block's one RDM value per face (level 7) is not. The viewer blends it
// across neighbouring faces. Stored in face_light.bin beside the atlas (section 4.6).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/bake/bake.h"
#include "rdm/bake/face_light_tracer.h"
#include "rdm/base/status.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "rdm/trace/integrator.h"

namespace rdm {

// One slot's exposed faces in increasing `faces` order. faces[i] is
// shared::faceLightTexel(voxel index, face); light[i] the cosine-weighted mean radiance
// (irradiance / pi, the unit of a level-7 texel) arriving at that face, direct sun excluded.
struct FaceLightSlot {
  glm::ivec3 slot{0};
  std::vector<uint32_t> faces;
  std::vector<glm::vec3> light;
};

// The face light's file name beside an atlas, in a shard and in a daemon job's outputs.
constexpr const char* kFaceLightFile = "face_light.bin";

// The stored order of face light slots: (i, j, k) lexicographic.
bool slotOrderLess(const glm::ivec3& a, const glm::ivec3& b);

// The digest a face light records and is checked against: sceneDigest of the scene without
// its bake settings and cameras, so a bake with --spp or --max-bounces overrides still
// belongs to its scene (as its atlas does); geometry, materials and lights count.
std::string faceLightSceneDigest(const Scene& scene);

struct FaceLight {
  std::string scene_digest;          // faceLightSceneDigest() of the scene it was baked for
  uint32_t spp = 0;                  // samples per face
  std::vector<FaceLightSlot> slots;  // the non-empty slots, (i, j, k) lexicographic
  size_t faceCount() const;
};

// A face is exposed when its voxel is solid and the voxel across it is empty or outside
// the grid. Sorted by shared::faceLightTexel.
std::vector<uint32_t> exposedFaces(const VoxelWorld& world, const glm::ivec3& slot);
// The exposed faces of every slot: what a full face light bake traces (spp paths each).
uint64_t exposedFaceCount(const VoxelWorld& world);

// A slot's light: spp paths per exposed face, from a uniform point on the face
// (shared::faceLightOrigin) in a cosine-distributed direction (Owen-scrambled Sobol' over the
// direction), each with the settings' bounces and seed; the mean of their radiance.
// Deterministic: the same world and settings give the same bits. FaceLightTracer traces them.

// How far a face light bake is: slots (the units of work) and their exposed faces (spp paths
// each) finished, of those of this shard, and the rays traced so far.
struct FaceLightProgress {
  size_t slots_done = 0, slots_total = 0;
  size_t faces_done = 0, faces_total = 0;
  uint64_t rays = 0;
};

struct FaceLightOptions {
  int threads = 0;  // 0: all cores
  int spp = 16;
  std::optional<BakeSettings> settings;  // bounces and seed; default: the scene's bake settings
  // A shard bakes the non-empty slots whose index in (i, j, k) order is shard_index modulo
  // shard_count; mergeFaceLights joins the shards' lights.
  int shard_index = 0, shard_count = 1;
  // Checked before each face and every 1024 paths (milliseconds); once true the bake returns
  // early with an incomplete light, which the caller discards (rdm serve: a cancel or a stop).
  // Null: runs to the end. Not stopping leaves the bits unchanged.
  const std::atomic<bool>* stop = nullptr;
  // Called on the calling thread: once before any work, about every 20 ms while slots bake,
  // and once after them unless `stop` was set. Empty: no reports. Does not change the bits.
  std::function<void(const FaceLightProgress&)> on_progress;
};
// Every non-empty slot, in parallel over slots; the result does not depend on `threads`.
FaceLight bakeFaceLight(const VoxelWorld& world, const Scene& scene,
                        const FaceLightOptions& options, PathStats* stats = nullptr);
// As bakeFaceLight, the paths traced by `tracer` (options.threads then counts only for
// finding the exposed faces); an error when the tracer's device fails.
Expected<FaceLight> bakeFaceLightOn(FaceLightTracer& tracer, const VoxelWorld& world,
                                    const Scene& scene, const FaceLightOptions& options,
                                    PathStats* stats = nullptr);

// The face lights of a complete set of shards as one: the same spp and scene, no slot twice,
// and exactly the slots of `rdms` (every non-empty slot has RDMs). Bit-identical to the
// one-process bake.
Expected<FaceLight> mergeFaceLights(std::vector<FaceLight> shards, const std::vector<RdmId>& rdms);

// After an edit from `before` to `after` (same grid size): re-bakes, with the light's spp and
// `settings`, the slots whose voxels changed and those of their 6-neighbours whose exposed
// faces changed, and drops slots that became empty. Other slots keep their light, which the
// edit may have made stale (docs/spec.md section 3.2, "Edits"). A re-baked slot holds the
// same bits as a full bake of `after`. Returns the re-baked slots, (i, j, k) lexicographic.
// `stop` as FaceLightOptions::stop: once true, returns early and `light` is incomplete.
std::vector<glm::ivec3> updateFaceLight(const VoxelWorld& before, const VoxelWorld& after,
                                        const BakeSettings& settings, FaceLight& light,
                                        int threads = 0, const std::atomic<bool>* stop = nullptr);
// As updateFaceLight, the re-baked slots traced by `tracer`.
Expected<std::vector<glm::ivec3>> updateFaceLightOn(FaceLightTracer& tracer,
                                                    const VoxelWorld& before,
                                                    const VoxelWorld& after,
                                                    const BakeSettings& settings, FaceLight& light,
                                                    const std::atomic<bool>* stop = nullptr);

// RGB9E5 (shared::decodeRgb9e5's layout), rounded to nearest; values above the largest
// (65408) clamp to it, negative and NaN components store 0.
uint32_t encodeRgb9e5(const glm::vec3& rgb);

// face_light.bin (docs/spec.md section 4.6), written atomically.
Status writeFaceLight(const std::string& path, const FaceLight& light);
// Refuses a file of another format or version, and one whose slots or faces are not
// in the stored order, naming what is wrong.
Expected<FaceLight> readFaceLight(const std::string& path);
// readFaceLight from the bytes of a file held in memory (a daemon download); `path` names
// them in errors.
Expected<FaceLight> decodeFaceLight(const std::string& bytes, const std::string& path);

}  // namespace rdm
