#include <algorithm>
#include <cstdio>
#include <string>

#include "api.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/bake_estimate.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/base/machine.h"
#include "rdm/scene/bake_settings_json.h"
#include "rdm/scene/world.h"
#include "rdm/service/resource_id.h"

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
  if (Status r = checkBakeSettingsKeys(j, "settings", {"quality"}); !r) return r;
  // A quality preset first (docs/spec.md section 3.1); the explicit keys win over it.
  BakeSettings defaults = s;
  if (j.contains("quality")) {
    auto preset = j["quality"].is_string() ? qualityPreset(j["quality"].get<std::string>())
                                           : qualityPreset("");
    if (!preset) {
      return Status::invalidField("settings.quality", "expected one of " + qualityPresetList());
    }
    defaults = withPreset(s, *preset);
  }
  auto settings =
      readBakeSettings(j, {"settings", defaults, BakeSettingsForm::kInput, {"quality"}});
  if (!settings) return settings.status();
  s = *settings;
  return {};
}

// "1.5 GiB (1610612736 bytes)": what a refusal names.
std::string bytesText(uint64_t bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%.1f GiB (%llu bytes)", double(bytes) / double(1ull << 30),
                (unsigned long long)bytes);
  return text;
}

// A placement's smallest JSON form, {"at":[0,0,0],"block":"a"}, and its comma.
constexpr long long kMinPlacementJsonBytes = 27;

}  // namespace

Problem sceneTooLarge(const std::string& detail) {
  return {413, "scene-too-large", "Scene too large for this server", detail, "placements"};
}

void resolveAdmissionLimits(ServerConfig& c) {
  if (c.max_job_memory <= 0) {
    const uint64_t physical = physicalMemoryBytes();
    c.max_job_memory = physical > 0 ? (long long)(physical / 2) : 1ll << 30;
  }
  if (c.max_placements <= 0) {
    const long long by_memory =
        c.max_job_memory / (long long)std::max<uint64_t>(1, minDaemonBytesPerPlacement());
    c.max_placements =
        std::max(1ll, std::min((long long)c.max_body / kMinPlacementJsonBytes, by_memory));
  }
}

std::optional<Problem> admitScene(const Scene& scene, const ServerConfig& c) {
  const SceneEstimate e = estimateScene(scene);
  const std::string parts =
      "; split the scene into smaller scenes (shards of the grid) or ask the operator for a "
      "larger limit";
  if ((long long)e.placements > c.max_placements) {
    return sceneTooLarge("the scene has " + std::to_string(e.placements) +
                         " placements, over this server's limit of " +
                         std::to_string(c.max_placements) + " (rdm serve --max-placements)" +
                         parts);
  }
  if (e.min_daemon_memory_bytes > uint64_t(c.max_job_memory)) {
    return sceneTooLarge(
        "a bake of this scene needs at least " + bytesText(e.min_daemon_memory_bytes) +
        " of memory even at max_hemisphere 2 (" + std::to_string(e.filled_placements) +
        " filled slots, world " + bytesText(e.world_bytes) +
        "), over this server's job memory limit of " + bytesText(uint64_t(c.max_job_memory)) +
        " (rdm serve --max-job-memory)" + parts);
  }
  return std::nullopt;
}

json estimateJson(const BakeEstimate& e) {
  return {{"rdms", e.rdms},
          {"texels", e.texels},
          {"pages", e.pages},
          {"atlas_bytes", e.atlas_bytes},
          {"memory_bytes", e.daemon_memory_bytes},
          {"disk_bytes", e.disk_bytes},
          {"cpu_seconds", e.cpu_seconds}};
}

std::optional<Problem> admitJob(const Scene& scene, const SubmitRequest& r, const ServerConfig& c,
                                json& estimate) {
  const VoxelWorld world = buildWorld(scene);
  const BakeEstimate e =
      estimateBake(world, r.settings, r.radiance, std::max(1, c.threads), {true, r.denoise});
  estimate = estimateJson(e);
  if (e.daemon_memory_bytes <= uint64_t(c.max_job_memory)) return std::nullopt;
  const std::string detail =
      "this job needs about " + bytesText(e.daemon_memory_bytes) +
      " of memory (estimate: " + std::to_string(e.rdms) + " RDMs, " + std::to_string(e.texels) +
      " stored texels, " + std::to_string(e.pages) +
      " atlas pages), over this server's job memory limit of " +
      bytesText(uint64_t(c.max_job_memory)) +
      " (rdm serve --max-job-memory); send a smaller settings.max_hemisphere (each halving "
      "divides the texels by about 4), \"radiance\": \"half\", or bake the scene in smaller "
      "parts (shards)";
  return Problem{422, "job-too-large", "Job too large for this server", detail,
                 "settings.max_hemisphere"};
}

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
        k != "face_light" && k != "denoise") {
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
    if (!radiance)
      return Status::invalidField("radiance", "expected \"float32\", \"half\" or \"bc6h\"");
    req.radiance = *radiance;
  }
  if (body.contains("denoise")) {
    if (!body["denoise"].is_boolean())
      return Status::invalidField("denoise", "expected true or false");
    req.denoise = body["denoise"].get<bool>();
    if (req.denoise && req.settings.estimator == Estimator::kNaive && req.settings.spp < 2) {
      return Status::invalidField(
          "denoise",
          "the naive estimator gives no standard error from 1 sample to guide the "
          "denoiser: use spp 2 or more, or the prefiltered estimator");
    }
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
