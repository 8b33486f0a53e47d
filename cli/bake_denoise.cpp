#include "bake_denoise.h"

#include <cstdio>

namespace rdm::cli {

DenoiseSettings denoiseSettings(const std::string& scope, const BakeSettings& bake) {
  DenoiseSettings settings;
  settings.across_slots = scope != "tile";
  settings.prefiltered = bake.estimator == Estimator::kPrefiltered;
  return settings;
}

Expected<std::unique_ptr<RdmSpill>> denoiseBake(const RdmSource& baked, const std::string& dir,
                                                const DenoiseSettings& settings,
                                                const DenoiseRun& run, BakeContext& context) {
  VulkanDenoiser* device = run.device;
  auto spill = RdmSpill::create(dir);
  if (!spill) return spill.status();
  DenoiseStats stats;
  if (Status s = denoiseRdms(baked, nullptr, **spill, settings, run.threads, stats, device); !s)
    return Status::error(s.code(), "denoise: " + s.message(), s.field());
  context.denoise = denoiseReportJson(settings, stats);
  context.denoise["device"] = device ? device->device().name : "cpu";
  if (!run.quiet) {
    const double filtered =
        stats.texels ? 100.0 * double(stats.filtered) / double(stats.texels) : 0.0;
    std::printf(
        "denoise:     %zu RDMs (%s, on %s), %.0f %% of texels filtered in %.2f s (%.2f CPU-s); "
        "relative standard error (sum over sum) %.2f %% -> %.2f %%\n",
        stats.rdms, settings.across_slots ? "across blocks" : "per tile",
        device ? device->device().name.c_str() : "the CPU", filtered, stats.seconds,
        stats.cpu_seconds, 100.0 * stats.relativeErrorBefore(), 100.0 * stats.relativeErrorAfter());
    std::fflush(stdout);
  }
  return std::move(*spill);
}

}  // namespace rdm::cli
