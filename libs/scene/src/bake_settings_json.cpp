#include "rdm/scene/bake_settings_json.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <type_traits>

namespace rdm {
namespace {

using nlohmann::json;

struct IntRange {
  long long lo = 0, hi = 0;
  bool power_of_two = false;
};

// One setting: its key in every JSON form and how it is written, read and checked. The reader
// and the checker of an integer setting share the row's one range.
struct Row {
  const char* key;
  bool in_report;  // bake_report.json carries it
  bool is_int;
  IntRange range;  // is_int only
  json (*write)(const BakeSettings& s);
  Status (*read)(const json& j, const std::string& field, BakeSettings& s);
  Status (*check)(const BakeSettings& s, const std::string& field);
  void (*legacy)(BakeSettings& s);  // job records written before the setting existed; null: none
};

std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string rangeText(const IntRange& r) {
  std::string text = "[";
  text += std::to_string(r.lo);
  text += ", ";
  text += std::to_string(r.hi);
  text += "]";
  return text;
}

Status checkRange(long long v, const IntRange& r, const std::string& field) {
  const bool inside = v >= r.lo && v <= r.hi && (!r.power_of_two || (v & (v - 1)) == 0);
  if (inside) return {};
  if (r.power_of_two) {
    return Status::invalidField(
        field, "must be a power of two in " + rangeText(r) + ", got " + std::to_string(v));
  }
  return Status::invalidField(field, "value " + std::to_string(v) + " outside " + rangeText(r));
}

// Any JSON integer; unsigned values past INT64_MAX read as INT64_MAX (outside every range).
Status readInteger(const json& j, const std::string& field, long long& out) {
  if (!j.is_number_integer()) return Status::invalidField(field, "expected an integer");
  out = j.is_number_unsigned()
            ? (long long)std::min<uint64_t>(j.get<uint64_t>(), uint64_t(INT64_MAX))
            : j.get<long long>();
  return {};
}

template <auto kField, IntRange kRange>
constexpr Row intRow(const char* key, bool in_report) {
  using T = std::remove_cvref_t<decltype(std::declval<BakeSettings&>().*kField)>;
  return {key,
          in_report,
          true,
          kRange,
          [](const BakeSettings& s) { return json(s.*kField); },
          [](const json& j, const std::string& field, BakeSettings& s) -> Status {
            long long v = 0;
            if (Status r = readInteger(j, field, v); !r) return r;
            if (Status r = checkRange(v, kRange, field); !r) return r;
            s.*kField = T(v);
            return {};
          },
          [](const BakeSettings& s, const std::string& field) {
            return checkRange((long long)(s.*kField), kRange, field);
          },
          nullptr};
}

constexpr Row estimatorRow() {
  return {"estimator",
          true,
          false,
          {},
          [](const BakeSettings& s) { return json(estimatorName(s.estimator)); },
          [](const json& j, const std::string& field, BakeSettings& s) -> Status {
            if (!j.is_string()) {
              return Status::invalidField(field, "expected a string, \"naive\" or \"prefiltered\"");
            }
            auto e = parseEstimator(j.get<std::string>());
            if (!e) return Status::invalidField(field, e.error());
            s.estimator = *e;
            return {};
          },
          [](const BakeSettings&, const std::string&) { return Status(); },
          [](BakeSettings& s) { s.estimator = Estimator::kNaive; }};
}

// The table: a new setting is one row. Readers take the rows in this order.
constexpr std::array kRows = {
    intRow<&BakeSettings::spp, IntRange{1, 65536}>("spp", true),
    intRow<&BakeSettings::max_bounces, IntRange{0, 64}>("max_bounces", true),
    intRow<&BakeSettings::seed, IntRange{0, 4294967295LL}>("seed", false),
    intRow<&BakeSettings::max_hemisphere, IntRange{2, 256, true}>("max_hemisphere", true),
    estimatorRow(),
};

constexpr IntRange kFaceLightSppRange{0, 65536};

}  // namespace

json bakeSettingsToJson(const BakeSettings& settings, BakeSettingsKeys keys) {
  json j = json::object();
  for (const Row& row : kRows) {
    if (keys == BakeSettingsKeys::kAll || row.in_report) j[row.key] = row.write(settings);
  }
  return j;
}

Status checkBakeSettingsKeys(const json& j, const std::string& path,
                             const std::vector<std::string>& extra_keys) {
  if (!j.is_object()) return Status::invalidField(path, "expected an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const bool known =
        std::any_of(kRows.begin(), kRows.end(), [&](const Row& r) { return it.key() == r.key; }) ||
        std::find(extra_keys.begin(), extra_keys.end(), it.key()) != extra_keys.end();
    if (!known) return Status::invalidField(join(path, it.key()), "unknown key");
  }
  return {};
}

Expected<BakeSettings> readBakeSettings(const json& j, const BakeSettingsRead& how) {
  const bool input = how.form == BakeSettingsForm::kInput;
  if (input) {
    if (Status s = checkBakeSettingsKeys(j, how.path, how.extra_keys); !s) return s;
  } else if (!j.is_object()) {
    return Status::invalidField(how.path, "expected an object");
  }
  BakeSettings out = input ? how.defaults : BakeSettings{};
  for (const Row& row : kRows) {
    const std::string field = join(how.path, row.key);
    const auto it = j.find(row.key);
    if (it == j.end()) {
      if (input) continue;
      if (how.form == BakeSettingsForm::kLegacyRecord && row.legacy) {
        row.legacy(out);
        continue;
      }
      return Status::invalidField(field, "required");
    }
    if (Status s = row.read(*it, field, out); !s) return s;
  }
  return out;
}

Status validateBakeSettings(const BakeSettings& settings, const std::string& path) {
  for (const Row& row : kRows) {
    if (Status s = row.check(settings, join(path, row.key)); !s) return s;
  }
  return {};
}

std::vector<BakeSettingRange> bakeSettingRanges() {
  std::vector<BakeSettingRange> out;
  for (const Row& row : kRows) {
    if (row.is_int) out.push_back({row.key, row.range.lo, row.range.hi, row.range.power_of_two});
  }
  return out;
}

Status checkFaceLightSpp(long long spp, const std::string& field) {
  return checkRange(spp, kFaceLightSppRange, field);
}

Expected<int> readFaceLightSpp(const json& j, const std::string& field) {
  long long v = 0;
  if (Status s = readInteger(j, field, v); !s) return s;
  if (Status s = checkFaceLightSpp(v, field); !s) return s;
  return int(v);
}

}  // namespace rdm
