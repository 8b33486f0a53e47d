#include "rdm/shard.h"

#include <cstdio>
#include <set>

#include <nlohmann/json.hpp>

#include "rdm/exr_io.h"
#include "rdm/file_util.h"
#include "rdm/hash.h"

namespace rdm {
namespace {

using nlohmann::json;

std::string rdmFileName(const RdmId& id) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "rdm_%d_%d_%d_L%d.exr", id.slot.x, id.slot.y, id.slot.z, id.level);
  return buf;
}

}  // namespace

std::string sceneDigest(const Scene& scene) {
  return contentHashHex(sceneToJson(scene));
}

Status writeShard(const std::string& dir, const ShardManifest& m,
                  const std::vector<RdmData>& rdms) {
  if (Status s = makeDirectories(dir); !s) return s;
  json j = {{"format", "rdm-shard"}, {"version", kShardVersion},       {"index", m.index},
            {"count", m.count},      {"scene_digest", m.scene_digest}, {"total_rdms", m.total_rdms},
            {"rdms", json::array()}};
  for (const RdmData& d : rdms) {
    if (Status s = writeExr(dir + "/" + rdmFileName(d.id), d.image, kRgbzChannels); !s) return s;
    j["rdms"].push_back({{"slot", {d.id.slot.x, d.id.slot.y, d.id.slot.z}},
                         {"level", d.id.level},
                         {"size", d.id.size},
                         {"skipped", d.skipped},
                         {"file", rdmFileName(d.id)}});
  }
  return writeFileAtomic(dir + "/shard.json", j.dump(1) + "\n");
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
    for (const json& r : j.at("rdms")) {
      RdmData d;
      d.id = {glm::ivec3(r.at("slot")[0].get<int>(), r.at("slot")[1].get<int>(),
                         r.at("slot")[2].get<int>()),
              r.at("level").get<int>(), r.at("size").get<int>()};
      d.skipped = r.at("skipped").get<std::array<bool, 6>>();
      auto image = readExr(dir + "/" + r.at("file").get<std::string>(), kRgbzChannels);
      if (!image) return image.status();
      if (image->width != 2 * d.id.size || image->height != 3 * d.id.size) {
        return Status::error(dir + ": RDM image " + r.at("file").get<std::string>() +
                             " has the wrong size");
      }
      d.image = std::move(*image);
      shard.rdms.push_back(std::move(d));
    }
  } catch (const std::exception& e) {
    return Status::error(dir + "/shard.json: " + e.what());
  }
  return shard;
}

Expected<std::vector<RdmData>> mergeShards(const std::vector<LoadedShard>& shards) {
  if (shards.empty()) return Status::error("no shards given");
  const ShardManifest& first = shards.front().manifest;
  std::set<int> seen;
  std::vector<RdmData> all;
  for (const LoadedShard& s : shards) {
    if (s.manifest.scene_digest != first.scene_digest || s.manifest.count != first.count) {
      return Status::error("shard " + std::to_string(s.manifest.index) +
                           " was baked from a different scene or split");
    }
    if (!seen.insert(s.manifest.index).second)
      return Status::error("shard " + std::to_string(s.manifest.index) + " given twice");
    all.insert(all.end(), s.rdms.begin(), s.rdms.end());
  }
  if (int(seen.size()) != first.count) {
    return Status::error("incomplete set: " + std::to_string(seen.size()) + " of " +
                         std::to_string(first.count) + " shards");
  }
  if (int(all.size()) != first.total_rdms) {
    return Status::error("shards hold " + std::to_string(all.size()) + " RDMs, the scene has " +
                         std::to_string(first.total_rdms));
  }
  return all;
}

}  // namespace rdm
