#include "rdm/bake/shard.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include <nlohmann/json.hpp>

#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"
#include "rdm/image/exr_io.h"

namespace rdm {
namespace {

using nlohmann::json;

// A larger S is a corrupt manifest: hemisphere sizes are at most 256 (docs/spec.md section 3).
constexpr int kMaxShardRdmSize = 4096;

std::string rdmFileName(const RdmId& id) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "rdm_%d_%d_%d_L%d.exr", id.slot.x, id.slot.y, id.slot.z, id.level);
  return buf;
}

}  // namespace

std::string sceneDigest(const Scene& scene) {
  return contentHashHex(sceneToJson(scene));
}

Status writeShard(const std::string& dir, const ShardManifest& m, const RdmSource& rdms) {
  if (Status s = makeDirectories(dir); !s) return s;
  json j = {{"format", "rdm-shard"}, {"version", kShardVersion},       {"index", m.index},
            {"count", m.count},      {"scene_digest", m.scene_digest}, {"total_rdms", m.total_rdms},
            {"rdms", json::array()}};
  if (!m.lighting.empty()) j["lighting"] = m.lighting;
  const std::vector<RdmId> ids = rdms.ids();
  std::vector<size_t> order(ids.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return canonicalLess(ids[a], ids[b]); });
  for (size_t i : order) {
    Status written;
    Status read = rdms.visit(i, [&](const RdmData& d) {
      written = writeExr(dir + "/" + rdmFileName(d.id), d.image, kRgbzChannels);
      j["rdms"].push_back({{"slot", {d.id.slot.x, d.id.slot.y, d.id.slot.z}},
                           {"level", d.id.level},
                           {"size", d.id.size},
                           {"skipped", d.skipped},
                           {"file", rdmFileName(d.id)}});
    });
    if (!read) return read;
    if (!written) return written;
  }
  return writeFileAtomic(dir + "/shard.json", j.dump(1) + "\n");
}

Status writeShard(const std::string& dir, const ShardManifest& manifest,
                  const std::vector<RdmData>& rdms) {
  return writeShard(dir, manifest, MemoryRdmSource(rdms));
}

Expected<LoadedShard> readShard(const std::string& dir) {
  auto text = readFileToString(dir + "/shard.json");
  if (!text) return text.status();
  LoadedShard shard;
  try {
    json j = json::parse(*text);
    if (j.at("format") != "rdm-shard")
      return Status::error(dir + "/shard.json: not an rdm-shard manifest");
    if (j.at("version") != kShardVersion) {
      return Status::error(dir + "/shard.json: rdm-shard version " + j.at("version").dump() +
                           " is not " + std::to_string(kShardVersion) +
                           " (this rdm's); bake the shard again");
    }
    shard.manifest = {j.at("index").get<int>(), j.at("count").get<int>(),
                      j.at("scene_digest").get<std::string>(), j.at("total_rdms").get<int>()};
    if (j.contains("lighting")) shard.manifest.lighting = j["lighting"].get<LightingFingerprint>();
    for (const json& r : j.at("rdms")) {
      ShardRdm d;
      d.id = {glm::ivec3(r.at("slot")[0].get<int>(), r.at("slot")[1].get<int>(),
                         r.at("slot")[2].get<int>()),
              r.at("level").get<int>(), r.at("size").get<int>()};
      if (d.id.size < 1 || d.id.size > kMaxShardRdmSize)
        return Status::error(dir + "/shard.json: an RDM size outside 1.." +
                             std::to_string(kMaxShardRdmSize));
      d.skipped = r.at("skipped").get<std::array<bool, 6>>();
      d.path = dir + "/" + r.at("file").get<std::string>();
      shard.rdms.push_back(std::move(d));
    }
  } catch (const std::exception& e) {
    return Status::error(dir + "/shard.json: " + e.what());
  }
  return shard;
}

Expected<ShardSet> mergeShards(std::vector<LoadedShard> shards) {
  if (shards.empty()) return Status::error("no shards given");
  const ShardManifest first = shards.front().manifest;
  std::set<int> seen;
  std::vector<ShardRdm> all;
  for (LoadedShard& s : shards) {
    if (s.manifest.scene_digest != first.scene_digest || s.manifest.count != first.count) {
      return Status::error("shard " + std::to_string(s.manifest.index) +
                           " was baked from a different scene or split");
    }
    if (!seen.insert(s.manifest.index).second)
      return Status::error("shard " + std::to_string(s.manifest.index) + " given twice");
    for (ShardRdm& r : s.rdms) all.push_back(std::move(r));
  }
  if (int(seen.size()) != first.count) {
    return Status::error("incomplete set: " + std::to_string(seen.size()) + " of " +
                         std::to_string(first.count) + " shards");
  }
  if (int(all.size()) != first.total_rdms) {
    return Status::error("shards hold " + std::to_string(all.size()) + " RDMs, the scene has " +
                         std::to_string(first.total_rdms));
  }
  return ShardSet(std::move(all));
}

std::vector<RdmId> ShardSet::ids() const {
  std::vector<RdmId> out;
  for (const ShardRdm& r : rdms_) out.push_back(r.id);
  return out;
}

Expected<std::vector<RdmDigest>> ShardSet::digests() const {
  std::vector<RdmDigest> out;
  for (size_t i = 0; i < rdms_.size(); ++i) {
    if (Status s = visit(i, [&](const RdmData& d) { out.push_back(digestRdm(d)); }); !s) return s;
  }
  return out;
}

Status ShardSet::visit(size_t i, const std::function<void(const RdmData&)>& use) const {
  RDM_CHECK(i < rdms_.size());
  const ShardRdm& r = rdms_[i];
  auto image = readExr(r.path, kRgbzChannels);
  if (!image) return image.status();
  if (image->width != 2 * r.id.size || image->height != 3 * r.id.size)
    return Status::error(r.path + ": RDM image has the wrong size");
  RdmData d;
  d.id = r.id;
  d.skipped = r.skipped;
  d.image = std::move(*image);
  d.stderr_rgb.assign(d.image.pixels.size() / 4 * 3, 0.0f);  // shards keep no errors
  use(d);
  return {};
}

}  // namespace rdm
