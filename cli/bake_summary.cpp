#include "bake_summary.h"

#include <algorithm>
#include <cstdio>

#include "progress.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/scene/bake_settings_json.h"

namespace rdm::cli {
namespace {

uint32_t mostSamples(const std::vector<RdmData>& rdms) {
  uint32_t most = 0;
  for (const RdmData& d : rdms) most = std::max(most, d.max_samples);
  return most;
}

std::string noiseLine(const BakeResult& result, const BakeContext& c) {
  const BakeReport& r = result.report;
  char buf[256];
  if (c.target_error > 0) {
    std::snprintf(buf, sizeof buf,
                  "mean relative standard error %.2f %% (max %.1f %%); target %.2f %%, "
                  "%d..%d spp per texel (most used: %u), S <= %d, %s estimator",
                  100.0 * r.mean_relative_error, 100.0 * r.max_relative_error,
                  100.0 * c.target_error, c.scene->bake.spp, c.scene->bake.spp * c.max_spp_factor,
                  mostSamples(result.rdms), c.scene->bake.max_hemisphere,
                  estimatorName(c.scene->bake.estimator));
  } else {
    std::snprintf(buf, sizeof buf,
                  "mean relative standard error %.2f %% (max %.1f %%) at %d spp, S <= %d, %s "
                  "estimator",
                  100.0 * r.mean_relative_error, 100.0 * r.max_relative_error, c.scene->bake.spp,
                  c.scene->bake.max_hemisphere, estimatorName(c.scene->bake.estimator));
  }
  return buf;
}

}  // namespace

nlohmann::json bakeReportJson(const BakeResult& result, const AtlasLayout* layout,
                              const BakeContext& c) {
  const BakeReport& r = result.report;
  nlohmann::json j = {{"rdms", r.rdms},
                      {"texels", r.texels},
                      {"useful_texels", usefulTexels(result.rdms)},
                      {"rays", r.rays},
                      {"seconds", r.seconds},
                      {"cpu_seconds", r.cpu_seconds},
                      {"peak_rdms_held", r.peak_rdms_held},
                      {"rays_per_second", r.seconds > 0 ? double(r.rays) / r.seconds : 0.0},
                      {"threads", c.threads},
                      {"backend", c.backend},
                      {"device", c.device},
                      {"faces_baked", r.faces_baked},
                      {"faces_skipped", r.faces_skipped},
                      {"target_error", c.target_error},
                      {"max_spp_factor", c.max_spp_factor},
                      {"mean_relative_error", r.mean_relative_error},
                      {"max_relative_error", r.max_relative_error},
                      {"effects_simulated", r.effects.describeSimulated()},
                      {"effects_skipped", r.effects.describeSkipped()}};
  j.update(bakeSettingsToJson(c.scene->bake, BakeSettingsKeys::kReport));
  if (!c.quality.empty()) j["quality"] = c.quality;  // also when the pilot was skipped
  if (c.prediction) {
    j["predicted"] = {{"seconds", c.prediction->seconds},
                      {"cpu_seconds", c.prediction->cpu_seconds},
                      {"mean_relative_error", c.prediction->relative_error},
                      {"pilot_seconds", c.prediction->pilot_seconds},
                      {"pilot_cpu_seconds", c.prediction->pilot_cpu_seconds},
                      {"pilot_slots", c.prediction->pilot_slots},
                      {"sampled_slots", c.prediction->sampled_slots},
                      {"spp2", c.prediction->spp2},
                      {"cheap", c.prediction->cheap},
                      {"free_cores", c.prediction->free_cores},
                      {"load_average", c.prediction->load_average},
                      {"slots", c.prediction->slots}};
  }
  if (!c.denoise.is_null()) j["denoise"] = c.denoise;
  if (layout) {
    j["occupancy"] = layout->occupancy();
    j["pages"] = layout->pages.size();
    j["radiance"] = radianceFormatName(layout->radiance);
  }
  return j;
}

void printBakeSummary(const BakeResult& result, const AtlasLayout* layout, const BakeContext& c) {
  const BakeReport& r = result.report;
  std::printf("RDMs:        %d (faces baked %d; %d faces skipped, hidden behind solid blocks)\n",
              r.rdms, r.faces_baked, r.faces_skipped);
  std::printf(
      "texels:      %stexels (%s useful)   rays: %srays\n", formatCount(double(r.texels)).c_str(),
      formatCount(double(usefulTexels(result.rdms))).c_str(), formatCount(double(r.rays)).c_str());
  std::printf("time:        %.2f s (%srays/s)\n", r.seconds,
              formatCount(r.seconds > 0 ? double(r.rays) / r.seconds : 0).c_str());
  if (layout && !layout->pages.empty()) {
    std::printf("atlas:       %zu page(s), page 0 %dx%d; useful texels fill %.1f %% of the pages\n",
                layout->pages.size(), layout->pages[0].width, layout->pages[0].height,
                100.0 * layout->occupancy());
  }
  std::printf("simulated:   %s\n", r.effects.describeSimulated().c_str());
  const std::string absent = r.effects.describeSkipped();
  if (absent == "nothing") {
    std::printf("not present: none (every effect is in the scene)\n");
  } else {
    std::printf("not present: %s (not in the scene, so not simulated)\n", absent.c_str());
  }
  std::printf("noise:       %s\n", noiseLine(result, c).c_str());
  if (c.prediction) {
    std::printf(
        "predicted:   %.2f s (%.2f CPU-s) and %.2f %% noise; measured %.2f s (%.2f CPU-s) and "
        "%.2f %%\n",
        c.prediction->seconds, c.prediction->cpu_seconds, 100.0 * c.prediction->relative_error,
        r.seconds, r.cpu_seconds, 100.0 * r.mean_relative_error);
  }
}

}  // namespace rdm::cli
