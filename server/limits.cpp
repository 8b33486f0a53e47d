#include <string>

#include "api.h"
#include "rdm/atlas.h"
#include "rdm/bake_prediction.h"
#include "rdm/resource_id.h"

namespace rdm::server {
namespace {

using nlohmann::json;

Status over(const std::string& field, long long value, long long limit) {
  return Status::invalidField(field, "value " + std::to_string(value) +
                                         " exceeds this server's limit " + std::to_string(limit));
}

Status readIntField(const json& j, const std::string& key, const std::string& path, long long lo,
                    long long hi, long long& out) {
  if (!j.contains(key)) return {};
  const json& v = j[key];
  if (!v.is_number_integer()) return Status::invalidField(path, "expected an integer");
  long long x =
      v.is_number_unsigned()
          ? (v.get<unsigned long long>() > (1ull << 62) ? (1ll << 62) : v.get<long long>())
          : v.get<long long>();
  if (x < lo || x > hi) {
    return Status::invalidField(path, "value " + std::to_string(x) + " outside [" +
                                          std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  out = x;
  return {};
}

Status readSettings(const json& j, BakeSettings& s) {
  if (!j.is_object()) return Status::invalidField("settings", "expected an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (k != "spp" && k != "max_bounces" && k != "seed" && k != "max_hemisphere" &&
        k != "estimator" && k != "quality") {
      return Status::invalidField("settings." + k, "unknown key");
    }
  }
  // A quality preset first (docs/spec.md section 3.1); the explicit keys win over it.
  if (j.contains("quality")) {
    auto preset = j["quality"].is_string() ? qualityPreset(j["quality"].get<std::string>())
                                           : qualityPreset("");
    if (!preset) {
      return Status::invalidField("settings.quality", "expected one of " + qualityPresetList());
    }
    s = withPreset(s, *preset);
  }
  long long spp = s.spp, bounces = s.max_bounces, seed = s.seed, hemi = s.max_hemisphere;
  if (Status r = readIntField(j, "spp", "settings.spp", 1, 65536, spp); !r) return r;
  if (Status r = readIntField(j, "max_bounces", "settings.max_bounces", 0, 64, bounces); !r)
    return r;
  if (Status r = readIntField(j, "seed", "settings.seed", 0, 4294967295ll, seed); !r) return r;
  if (Status r = readIntField(j, "max_hemisphere", "settings.max_hemisphere", 2, 256, hemi); !r)
    return r;
  if (hemi & (hemi - 1)) {
    return Status::invalidField("settings.max_hemisphere", "must be a power of two in 2..256");
  }
  Estimator estimator = s.estimator;
  if (j.contains("estimator") && (!j["estimator"].is_string() ||
                                  !parseEstimator(j["estimator"].get<std::string>(), estimator))) {
    return Status::invalidField("settings.estimator", "must be \"naive\" or \"prefiltered\"");
  }
  s = {int(spp), int(bounces), uint32_t(seed), int(hemi), estimator};
  return {};
}

}  // namespace

Status checkSettingsLimits(const BakeSettings& s, const ServerConfig& c,
                           const std::string& prefix) {
  if (s.spp > c.max_spp) return over(prefix + ".spp", s.spp, c.max_spp);
  if (s.max_hemisphere > c.max_hemisphere)
    return over(prefix + ".max_hemisphere", s.max_hemisphere, c.max_hemisphere);
  return {};
}

Status sceneWithinLimits(const Scene& scene, const ServerConfig& c) {
  for (int a = 0; a < 3; ++a) {
    if (scene.size[a] > c.max_grid)
      return over("size[" + std::to_string(a) + "]", scene.size[a], c.max_grid);
  }
  if (scene.face_light_spp > c.max_spp)
    return over("bake.face_light_spp", scene.face_light_spp, c.max_spp);
  return checkSettingsLimits(scene.bake, c, "bake");
}

Expected<SubmitRequest> parseBakeRequest(const json& body, const Scene& current,
                                         const ServerConfig& c) {
  if (!body.is_object()) return Status::invalid("", "the request body must be a JSON object");
  SubmitRequest req;
  req.settings = current.bake;
  for (auto it = body.begin(); it != body.end(); ++it) {
    const std::string& k = it.key();
    if (k != "version" && k != "settings" && k != "mode" && k != "base_job" && k != "radiance" &&
        k != "face_light") {
      return Status::invalidField(k, "unknown key");
    }
  }
  long long version = 0;
  if (Status s = readIntField(body, "version", "version", 1, 1ll << 50, version); !s) return s;
  req.version = version;
  if (body.contains("settings")) {
    if (Status s = readSettings(body["settings"], req.settings); !s) return s;
  }
  if (Status s = checkSettingsLimits(req.settings, c, "settings"); !s) return s;
  if (body.contains("mode")) {
    if (!body["mode"].is_string() || !parseMode(body["mode"].get<std::string>(), req.mode)) {
      return Status::invalidField("mode", "expected \"full\", \"exact\" or \"fast\"");
    }
  }
  if (body.contains("radiance")) {
    auto radiance = body["radiance"].is_string()
                        ? parseRadianceFormat(body["radiance"].get<std::string>())
                        : parseRadianceFormat("");
    if (!radiance) return Status::invalidField("radiance", "expected \"float32\" or \"half\"");
    req.radiance = *radiance;
  }
  long long face_light = current.face_light_spp;  // absent: the scene's
  if (Status s = readIntField(body, "face_light", "face_light", 0, c.max_spp, face_light); !s)
    return s;
  req.face_light_spp = int(face_light);
  if (body.contains("base_job")) {
    const json& b = body["base_job"];
    if (!b.is_string() || !validId(b.get<std::string>(), 'j')) {
      return Status::invalidField("base_job", "expected a job id");
    }
    if (req.mode == BakeMode::kFull)
      return Status::invalidField("base_job", "only for modes exact and fast");
    req.base_job = b.get<std::string>();
  }
  return req;
}

}  // namespace rdm::server
