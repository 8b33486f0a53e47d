// What a bake will take, computed before it runs (docs/api.md, "Admission"): RDMs, texels,
// atlas pages, memory, disk and CPU time of a scene at given settings. The daemon refuses an
// upload or a job whose estimate exceeds its limits instead of running out of memory.
#pragma once

#include <cstddef>
#include <cstdint>

#include "rdm/atlas/atlas.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct BakeEstimate {
  size_t blocks = 0;  // non-empty slots
  size_t rdms = 0;
  uint64_t texels = 0;  // stored face texels (faces skipped by section 3's rule excluded)
  int pages = 0;
  // Page texels x 16 bytes (float32 R, G, B, Z), 10 bytes (half R, G, B, float Z) or 3
  // bytes (BC6H R, G, B, half Z): the pixel bytes of every atlas page, without containers.
  uint64_t atlas_bytes = 0;
  uint64_t world_bytes = 0;          // the compiled VoxelWorld
  uint64_t peak_memory_bytes = 0;    // `rdm bake` in one process (RDMs streamed to the atlas)
  uint64_t daemon_memory_bytes = 0;  // one `rdm serve` job: it holds every planned RDM
  // A daemon job's files at their largest: units.log, rdms.store and the atlas pages.
  uint64_t disk_bytes = 0;
  double cpu_seconds = 0.0;  // thread-seconds of path tracing
};

// What a bake keeps and writes beside its RDMs.
struct BakeExtras {
  bool slot_sets = false;  // `rdm bake` records slot sets for rdms.bin (a daemon job always does)
  bool denoise = false;    // the denoiser writes its RDMs to a second spill file
};

// `threads` is the bake's worker count (>= 1); it scales the RDMs in flight of `rdm bake`.
BakeEstimate estimateBake(const VoxelWorld& world, const BakeSettings& settings,
                          RadianceFormat radiance, int threads, const BakeExtras& extras = {});

// The bytes of one RDM's slot sets held as runs (rdm/bake/slot_set.h) in `world`: they grow
// with the grid's extent, the runs a ray across it breaks into.
uint64_t slotSetBytesPerRdm(const VoxelWorld& world);

// Bounds from the scene alone, before anything is built: a scene whose world or smallest
// possible job cannot fit is refused without building its world.
struct SceneEstimate {
  size_t placements = 0;
  size_t filled_placements = 0;  // of non-empty blocks: each slot has at least its level-7 RDM
  uint64_t world_bytes = 0;      // an upper bound of the compiled world
  // The least a daemon job of the scene holds: every filled slot's level-7 RDM at S = 2.
  uint64_t min_daemon_memory_bytes = 0;
};
SceneEstimate estimateScene(const Scene& scene);
// The least one placement of a non-empty block adds to a daemon job (its level-7 RDM at S = 2).
uint64_t minDaemonBytesPerPlacement();

// The heap bytes of a compiled world (its slot grid, oriented blocks and emitters).
uint64_t worldBytes(const VoxelWorld& world);

}  // namespace rdm
