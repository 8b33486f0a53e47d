#include "rdm/scene/lighting_fingerprint.h"

#include <nlohmann/json.hpp>

#include "rdm/base/hash.h"
#include "rdm/scene/bake_settings_json.h"

namespace rdm {
namespace {

const char* const kParts[] = {"geometry",       "palette", "sun", "sky",
                              "emission_scale", "ambient", "bake"};

}  // namespace

LightingFingerprint lightingFingerprint(const Scene& scene, const BakeSettings& settings) {
  nlohmann::json j = nlohmann::json::parse(sceneToJson(scene));
  j["bake"] = bakeSettingsToJson(settings);
  j["bake"].erase("face_light_spp");
  const nlohmann::json geometry = {{"size", j.value("size", nlohmann::json())},
                                   {"blocks", j.value("blocks", nlohmann::json())},
                                   {"placements", j.value("placements", nlohmann::json())}};
  LightingFingerprint out;
  for (const char* part : kParts) {
    const nlohmann::json& value =
        std::string(part) == "geometry" ? geometry : j.value(part, nlohmann::json());
    out[part] = contentHashHex(value.dump());
  }
  return out;
}

std::vector<std::string> lightingDifferences(const LightingFingerprint& baked,
                                             const LightingFingerprint& scene) {
  std::vector<std::string> out;
  if (baked.empty() || scene.empty()) return out;
  for (const char* part : kParts) {
    auto a = baked.find(part), b = scene.find(part);
    if (a == baked.end() || b == scene.end() || a->second != b->second) out.push_back(part);
  }
  return out;
}

}  // namespace rdm
