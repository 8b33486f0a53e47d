// The RDM bake (docs/spec.md section 3): baking the RDMs of rdm_list.h with the path tracer on
// all cores. Results are bit-identical whatever the thread count or sharding.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/bake/rdm_list.h"
#include "rdm/image/image.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct BakeProgress {
  int rdms_done = 0, rdms_total = 0;
  uint64_t rays = 0;
  double seconds = 0.0;
  uint64_t texels_done = 0, texels_total = 0;  // work-weighted: each finished unit's texels
};

struct BakeOptions {
  int threads = 0;                       // 0: all cores
  double target_error = 0.0;             // > 0: sample each texel until relative std error < E
  int max_spp_factor = 16;               // target-error mode stops at spp * factor samples
  int shard_index = 0, shard_count = 1;  // bake RDMs with canonical index % count == index
  bool all_effects = false;              // compile every effect in (for equivalence tests)
  bool record_slot_sets = false;         // fill RdmData full_set / first_set (incremental rebakes)
  // When set (bakeRdms only): CPU seconds of each RDM's units, in the bake's canonical order.
  // A prefiltered slot's radiance map is charged to the unit that traced it, so only sums over
  // a slot's RDMs are meaningful.
  std::vector<double>* rdm_cpu_seconds = nullptr;
  std::function<void(const BakeProgress&)> on_progress;  // called from the calling thread
  const std::atomic<bool>* cancel = nullptr;
  // bakeRdms only: called once per RDM as soon as all its units ran, from a worker thread,
  // concurrently for distinct RDMs. With it set, an RDM's texels exist only from its first
  // unit until this call returns (the result keeps id, skipped and max_samples), and units
  // run slot by slot, so the bake holds the RDMs and radiance maps in flight, not all of them.
  // With record_slot_sets the RDM passed here carries its slot sets, which the result then
  // lacks as well: a caller keeps what it needs of them here (a 20,000-RDM world's sets as
  // u32 lists took 1.7 GB more than the bake, docs/performance.md).
  std::function<void(const RdmData&)> on_rdm_done;
};

struct BakeReport {
  int rdms = 0;
  uint64_t texels = 0;
  uint64_t rays = 0;
  int faces_baked = 0, faces_skipped = 0;
  double seconds = 0.0;
  // CPU time of the bake summed over its threads: on a shared machine it varies far less
  // between runs than `seconds` does.
  double cpu_seconds = 0.0;
  double mean_relative_error = 0.0;  // mean over baked texels of stderr / value (luminance)
  double max_relative_error = 0.0;
  EffectSet effects;
  bool cancelled = false;
  // The most RDMs whose texels (2S x 3S x 7 floats each) the bake held at once: every RDM,
  // unless BakeOptions::on_rdm_done streams them out.
  int peak_rdms_held = 0;
};

struct BakeResult {
  std::vector<RdmData> rdms;  // canonical order (of this shard)
  BakeReport report;
};

// One work unit: at most 64 x 64 texels of one face of one RDM (a whole face at level 7).
struct BakeUnit {
  int rdm = 0, face = 0, x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// Slot sets one work unit recorded (BakeOptions::record_slot_sets), sorted and unique.
struct UnitSlotSets {
  std::vector<uint32_t> full, first;
  bool smooth_vertex = false;
};

// A bake split into work units that a scheduler may run in any order, on any threads, or
// restore from storage: the result is bit-identical whatever the order. bakeRdms is a
// thread pool over one session; the daemon interleaves units of several sessions.
class BakeSession {
 public:
  BakeSession(const VoxelWorld& world, const BakeSettings& settings, const std::vector<RdmId>& rdms,
              const BakeOptions& options);
  ~BakeSession();
  BakeSession(const BakeSession&) = delete;
  BakeSession& operator=(const BakeSession&) = delete;

  const std::vector<BakeUnit>& units() const;
  // Runs unit i, writing its texels into rdms(); safe concurrently for distinct units.
  // Returns the rays traced.
  uint64_t runUnit(size_t i);
  // The same, moving the unit's slot sets into `sets` (a scheduler that persists units
  // keeps them with the unit; finish() then merges only the sets left in the session).
  uint64_t runUnit(size_t i, UnitSlotSets* sets);
  std::vector<RdmData>& rdms();
  // The most RDMs whose texels were allocated at once (all of them unless lazily allocated).
  int peakRdmsHeld() const;
  // RDM r with its texels allocated (lazily allocated sessions), for restoring units into it.
  RdmData& rdmTexels(size_t r);
  // After every unit of RDM r ran: passes it to `done` with its max_samples and, when
  // recording, its slot sets (those runUnit did not hand out) set, then frees its texels and
  // sets (requires BakeOptions::on_rdm_done, which allocates them lazily).
  void releaseRdm(size_t r, const std::function<void(const RdmData&)>& done);
  // Merges slot sets and summarises; call once, after every unit ran or was restored.
  BakeResult finish(double seconds, uint64_t rays, bool cancelled);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// This shard's RDMs in canonical order (canonical index % shard_count == shard_index).
std::vector<RdmId> shardRdms(const VoxelWorld& world, const BakeSettings& settings, int shard_index,
                             int shard_count);

// A thread pool over one BakeSession; on_progress sees a 0 % report before any work, then
// one about every 20 ms, and a last one unless the bake was cancelled.
BakeResult bakeRdms(const VoxelWorld& world, const BakeSettings& settings,
                    const std::vector<RdmId>& rdms, const BakeOptions& options);
BakeResult bakeScene(const VoxelWorld& world, const BakeSettings& settings,
                     const BakeOptions& options);

}  // namespace rdm
