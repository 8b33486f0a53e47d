// The one JSON form of BakeSettings and its one table of valid ranges: the scene's "bake", a
// job record's and an atlas delta's "settings", bake_report.json and a bake request's
// "settings" are all written, read and range-checked here. A new setting is a BakeSettings
// field (scene.h) and a row of the table in bake_settings_json.cpp.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"

namespace rdm {

// Which keys a writer emits. Every object is a nlohmann::json (keys in sorted order), so the
// key set alone fixes the bytes.
enum class BakeSettingsKeys {
  kAll,     // scene file "bake", job record and atlas delta "settings"
  kReport,  // bake_report.json: the table's report keys (all but seed)
};

// How a reader treats absent and unknown keys.
enum class BakeSettingsForm {
  kInput,         // a scene's "bake" or a request's "settings": absent keys keep the defaults,
                  // unknown keys are refused
  kRecord,        // an atlas delta: every key required, unknown keys ignored
  kLegacyRecord,  // a job record: as kRecord, but a key absent from records written before the
                  // setting existed takes the table's legacy value (estimator: naive)
};

struct BakeSettingsRead {
  std::string path;       // field path of the object, "bake" or "settings"
  BakeSettings defaults;  // kInput: the values of absent keys
  BakeSettingsForm form = BakeSettingsForm::kInput;
  std::vector<std::string> extra_keys;  // kInput: keys the caller reads itself (not refused)
};

// An integer setting's inclusive range, as the table holds it.
struct BakeSettingRange {
  std::string key;
  long long lo = 0, hi = 0;
  bool power_of_two = false;  // the value must also be a power of two
};

nlohmann::json bakeSettingsToJson(const BakeSettings& settings,
                                  BakeSettingsKeys keys = BakeSettingsKeys::kAll);

// Reads and range-checks `j`; a refusal names the field (e.g. "bake.spp") and what it allows.
Expected<BakeSettings> readBakeSettings(const nlohmann::json& j, const BakeSettingsRead& how);

// kInput's key check alone: `j` is an object whose keys are settings or `extra_keys`.
Status checkBakeSettingsKeys(const nlohmann::json& j, const std::string& path,
                             const std::vector<std::string>& extra_keys = {});

// The table's range checks on settings built in memory (CLI flags, presets); fields are named
// `path` + "." + key.
Status validateBakeSettings(const BakeSettings& settings, const std::string& path = "bake");

// The integer rows of the table, in table order (tests and docs enumerate them).
std::vector<BakeSettingRange> bakeSettingRanges();

// bake.face_light_spp (a Scene field beside the settings, docs/spec.md section 2): 0..65536.
Status checkFaceLightSpp(long long spp, const std::string& field = "bake.face_light_spp");
// Reads bake.face_light_spp's JSON value with checkFaceLightSpp's range.
Expected<int> readFaceLightSpp(const nlohmann::json& j, const std::string& field);

}  // namespace rdm
