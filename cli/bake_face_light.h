// The face light phase of `rdm bake` (docs/spec.md section 3.2): baked after the RDMs on the
// bake's backend, with its own progress, stopped by Ctrl-C like the RDM phase.
#pragma once

#include <string>

#include "rdm/bake/face_light.h"

namespace rdm::cli {

struct FaceLightBake {
  FaceLight light;
  double seconds = 0.0;  // wall time of the phase
};

struct FaceLightPhase {
  int spp = 0, threads = 0;  // threads: 0 for all cores
  int shard_index = 0, shard_count = 1;
  bool quiet = false;                 // no progress
  FaceLightTracer* tracer = nullptr;  // the Vulkan backend's; null: the CPU
};

// Bakes this shard's face light, showing progress ("face light", slots and faces) unless quiet.
// A Ctrl-C (interrupted()) stops it early with an incomplete light, which must not be written.
// An error only when the tracer's device fails.
Expected<FaceLightBake> bakeFaceLightPhase(const VoxelWorld& world, const Scene& scene,
                                           const FaceLightPhase& phase);

// Writes DIR/face_light.bin and prints its summary line beside the RDM bake's time.
[[nodiscard]] Status writeFaceLightOutput(const std::string& dir, const FaceLightBake& bake,
                                          double rdm_seconds);

}  // namespace rdm::cli
