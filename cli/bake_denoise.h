// The denoise phase of `rdm bake --denoise` (docs/denoise.md): after the RDMs are baked and
// before anything is written, every RDM is filtered into a second spill file, which the
// writers then read instead of the bake's.
#pragma once

#include <memory>
#include <string>

#include "bake_summary.h"
#include "rdm/bake/denoise.h"
#include "rdm/vulkan/vulkan_denoise.h"

namespace rdm::cli {

// --denoise-scope: "blocks" (across block borders) or "tile" (each face's own map); the
// bake's estimator.
DenoiseSettings denoiseSettings(const std::string& scope, const BakeSettings& bake);

struct DenoiseRun {
  int threads = 0;                   // 0: all cores
  VulkanDenoiser* device = nullptr;  // filter there instead of on the CPU
  bool quiet = false;
};

// The filtered RDMs of `baked`, spilled in `dir`; prints one line (unless quiet) and puts
// the report's "denoise" object into context.denoise.
Expected<std::unique_ptr<RdmSpill>> denoiseBake(const RdmSource& baked, const std::string& dir,
                                                const DenoiseSettings& settings,
                                                const DenoiseRun& run, BakeContext& context);

}  // namespace rdm::cli
