#include "bake_face_light.h"

#include <chrono>
#include <cstdio>

#include "interrupt.h"
#include "progress.h"

namespace rdm::cli {

Expected<FaceLightBake> bakeFaceLightPhase(const VoxelWorld& world, const Scene& scene,
                                           const FaceLightPhase& phase) {
  FaceLightBake out;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  ProgressReporter progress("slots", "face light");
  FaceLightOptions options;
  options.threads = phase.threads, options.spp = phase.spp;
  options.shard_index = phase.shard_index, options.shard_count = phase.shard_count;
  options.stop = interruptFlag();
  options.on_progress = [&](const FaceLightProgress& p) {
    announceInterrupt("bake");
    if (phase.quiet) return;
    // Weighted by faces, each spp paths; the line counts slots, the units of work.
    progress.update(double(p.faces_done), double(p.faces_total), int(p.slots_done),
                    int(p.slots_total), p.rays, elapsed());
  };
  CpuFaceLightTracer cpu(phase.threads);
  auto light = bakeFaceLightOn(phase.tracer ? *phase.tracer : cpu, world, scene, options);
  announceInterrupt("bake");  // a Ctrl-C after the last report
  progress.finish();
  if (!light) return light.status();
  out.light = std::move(*light);
  out.seconds = elapsed();
  return out;
}

Status writeFaceLightOutput(const std::string& dir, const FaceLightBake& bake, double rdm_seconds) {
  if (Status s = writeFaceLight(dir + "/" + kFaceLightFile, bake.light); !s) return s;
  std::printf("face light:  %zu faces of %zu slots, %u spp, %.2f s (%.0f %% of the RDM bake)\n",
              bake.light.faceCount(), bake.light.slots.size(), bake.light.spp, bake.seconds,
              rdm_seconds > 0.0 ? 100.0 * bake.seconds / rdm_seconds : 0.0);
  return {};
}

}  // namespace rdm::cli
