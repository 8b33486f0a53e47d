// The plan of one Vulkan bake (docs/vulkan.md): the RDM images with their exact central
// depths (on the CPU, exactCentralDepth, as the CPU backend), and the texel jobs the kernel
// traces: an RDM's texels (naive estimator, or a slot without a radiance map), or a radiance
// map's texels (prefiltered estimator, docs/spec.md section 3.1) from which the host derives
// every level of that face with the CPU's FaceMapBuilder and FaceMapDerivation.
#pragma once

#if RDM_HAVE_VULKAN

#include <memory>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/face_map.h"
#include "shared/rdm_gpu_layout.h"

namespace rdm::vkbake {

// A texel job and the group its samples accumulate into: the texel itself, or at level 7
// every texel of the face (the face mean).
struct Job {
  int rdm;    // the RDM of an RDM texel; -1 for a map texel
  int map;    // the radiance map of a map texel; -1 for an RDM texel
  int owner;  // slot-set owner (an RDM, or a slot's maps): non-decreasing in job order
  int face, i, j;
  int group;  // index of the group's first job
  gpu::GpuJob gpu;
};

// One face's radiance map: traced as `size` x `size` map texel jobs, then derived into that
// face of each consumer and freed.
struct PlannedMap {
  glm::ivec3 slot;
  int face, size;
  std::unique_ptr<FaceMapBuilder> builder;
  std::vector<int> consumers;  // RDMs whose face `face` derives from this map
  int jobs_left = 0;
  bool started = false;  // a job of it was dispatched (its consumers' texels exist)
};

// Slot sets gathered for an owner that is not an RDM (a slot's maps), merged into each RDM
// that consumes them at the end of the bake.
struct OwnerSets {
  int rdm = -1;  // the RDM this owner is, or -1 for a slot's maps
  std::vector<uint32_t> full, first;
  bool smooth = false;
};

struct BakePlan {
  std::vector<Job> jobs;  // in (owner, face, j, i) order
  std::vector<PlannedMap> maps;
  std::vector<OwnerSets> owners;
  std::vector<int> pending;     // per RDM: texel jobs or map faces not finished yet
  std::vector<int> maps_owner;  // per RDM: the owner of the maps it derives from, or -1
};

// Fills result.rdms (ids, skipped faces, max_samples; no texels yet) and the report's face
// counts, and returns the jobs.
BakePlan planBake(const VoxelWorld& world, const BakeSettings& settings,
                  const std::vector<RdmId>& rdms, BakeResult& result);

// An RDM's texels, allocated when its first job is dispatched: the image with every texel's
// exact central depth (exactCentralDepth, as the CPU) and, when recording, the central
// rays' slots in both sets; freed when a streaming bake hands the RDM out.
class RdmTexels {
 public:
  RdmTexels(const VoxelWorld& world, bool record, size_t rdms);
  ~RdmTexels();
  void ensure(RdmData& rdm, size_t r);
  void release(RdmData& rdm);
  int peakHeld() const { return peak_; }

 private:
  class CentralSlots;
  const VoxelWorld& world_;
  const bool record_;
  std::unique_ptr<CentralSlots> central_;
  std::vector<uint8_t> allocated_;
  int held_ = 0, peak_ = 0;
};

// Writes face `face` of `rdm`'s RGB and standard errors from its finished map.
void deriveFace(const FaceMap& map, int face, RdmData& rdm);

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
