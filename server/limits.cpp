#include <string>

#include "api.h"
#include "rdm/bake_prediction.h"
#include "rdm/resource_id.h"

namespace rdm::server {
namespace {

using nlohmann::json;

std::optional<Problem> over(const std::string& field, long long value, long long limit) {
  return invalidField("field '" + field + "': value " + std::to_string(value) +
                          " exceeds this server's limit " + std::to_string(limit),
                      field);
}

std::optional<Problem> readIntField(const json& j, const std::string& key, const std::string& path,
                                    long long lo, long long hi, long long& out) {
  if (!j.contains(key)) return std::nullopt;
  const json& v = j[key];
  if (!v.is_number_integer())
    return invalidField("field '" + path + "': expected an integer", path);
  long long x =
      v.is_number_unsigned()
          ? (v.get<unsigned long long>() > (1ull << 62) ? (1ll << 62) : v.get<long long>())
          : v.get<long long>();
  if (x < lo || x > hi) {
    return invalidField("field '" + path + "': value " + std::to_string(x) + " outside [" +
                            std::to_string(lo) + ", " + std::to_string(hi) + "]",
                        path);
  }
  out = x;
  return std::nullopt;
}

std::optional<Problem> readSettings(const json& j, BakeSettings& s) {
  if (!j.is_object()) return invalidField("field 'settings': expected an object", "settings");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (k != "spp" && k != "max_bounces" && k != "seed" && k != "max_hemisphere" &&
        k != "estimator" && k != "quality") {
      return invalidField("field 'settings." + k + "': unknown key", "settings." + k);
    }
  }
  // A quality preset first (docs/spec.md section 3.1); the explicit keys win over it.
  if (j.contains("quality")) {
    auto preset = j["quality"].is_string() ? qualityPreset(j["quality"].get<std::string>())
                                           : qualityPreset("");
    if (!preset) {
      return invalidField("field 'settings.quality': expected one of " + qualityPresetList(),
                          "settings.quality");
    }
    s = withPreset(s, *preset);
  }
  long long spp = s.spp, bounces = s.max_bounces, seed = s.seed, hemi = s.max_hemisphere;
  if (auto p = readIntField(j, "spp", "settings.spp", 1, 65536, spp)) return p;
  if (auto p = readIntField(j, "max_bounces", "settings.max_bounces", 0, 64, bounces)) return p;
  if (auto p = readIntField(j, "seed", "settings.seed", 0, 4294967295ll, seed)) return p;
  if (auto p = readIntField(j, "max_hemisphere", "settings.max_hemisphere", 2, 256, hemi)) return p;
  if (hemi & (hemi - 1)) {
    return invalidField("field 'settings.max_hemisphere': must be a power of two in 2..256",
                        "settings.max_hemisphere");
  }
  Estimator estimator = s.estimator;
  if (j.contains("estimator") && (!j["estimator"].is_string() ||
                                  !parseEstimator(j["estimator"].get<std::string>(), estimator))) {
    return invalidField("field 'settings.estimator': must be \"naive\" or \"prefiltered\"",
                        "settings.estimator");
  }
  s = {int(spp), int(bounces), uint32_t(seed), int(hemi), estimator};
  return std::nullopt;
}

}  // namespace

std::optional<Problem> checkSettingsLimits(const BakeSettings& s, const ServerConfig& c,
                                           const std::string& prefix) {
  if (s.spp > c.max_spp) return over(prefix + ".spp", s.spp, c.max_spp);
  if (s.max_hemisphere > c.max_hemisphere)
    return over(prefix + ".max_hemisphere", s.max_hemisphere, c.max_hemisphere);
  return std::nullopt;
}

Status sceneWithinLimits(const Scene& scene, const ServerConfig& c) {
  std::optional<Problem> p;
  for (int a = 0; a < 3 && !p; ++a) {
    if (scene.size[a] > c.max_grid)
      p = over("size[" + std::to_string(a) + "]", scene.size[a], c.max_grid);
  }
  if (!p) p = checkSettingsLimits(scene.bake, c, "bake");
  return p ? Status::invalid(p->field, p->detail) : Status();
}

std::variant<SubmitRequest, Problem> parseBakeRequest(const json& body, const Scene& current,
                                                      const ServerConfig& c) {
  if (!body.is_object()) return invalidField("the request body must be a JSON object");
  SubmitRequest req;
  req.settings = current.bake;
  for (auto it = body.begin(); it != body.end(); ++it) {
    const std::string& k = it.key();
    if (k != "version" && k != "settings" && k != "mode" && k != "base_job") {
      return invalidField("field '" + k + "': unknown key", k);
    }
  }
  long long version = 0;
  if (auto p = readIntField(body, "version", "version", 1, 1ll << 50, version)) return *p;
  req.version = version;
  if (body.contains("settings")) {
    if (auto p = readSettings(body["settings"], req.settings)) return *p;
  }
  if (auto p = checkSettingsLimits(req.settings, c, "settings")) return *p;
  if (body.contains("mode")) {
    if (!body["mode"].is_string() || !parseMode(body["mode"].get<std::string>(), req.mode)) {
      return invalidField("field 'mode': expected \"full\", \"exact\" or \"fast\"", "mode");
    }
  }
  if (body.contains("base_job")) {
    const json& b = body["base_job"];
    if (!b.is_string() || !validId(b.get<std::string>(), 'j')) {
      return invalidField("field 'base_job': expected a job id", "base_job");
    }
    if (req.mode == BakeMode::kFull)
      return invalidField("field 'base_job': only for modes exact and fast", "base_job");
    req.base_job = b.get<std::string>();
  }
  return req;
}

}  // namespace rdm::server
