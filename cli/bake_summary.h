// What `rdm bake` prints and writes to bake_report.json after a bake.
#pragma once

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/scene/scene.h"

namespace rdm::cli {

struct BakeContext {
  const Scene* scene = nullptr;
  double target_error = 0.0;
  int max_spp_factor = 16;
  int threads = 0;
  std::string backend, device;
  const BakePrediction* prediction = nullptr;  // with --quality or --predict
  std::string quality;
  nlohmann::json denoise;  // bake_report.json's "denoise" (denoiseReportJson); null: off
};

nlohmann::json bakeReportJson(const BakeResult& result, const AtlasLayout* layout,
                              const BakeContext& context);

void printBakeSummary(const BakeResult& result, const AtlasLayout* layout,
                      const BakeContext& context);

}  // namespace rdm::cli
