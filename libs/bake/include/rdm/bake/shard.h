// Shard outputs of `rdm bake --shard I/N` and their merge (deploy issue): a shard directory
// holds shard.json and one RGBZ EXR per RDM; merging packs canonically, so the merged atlas
// equals a one-process bake byte for byte.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/base/status.h"
#include "rdm/scene/lighting_fingerprint.h"

namespace rdm {

struct ShardManifest {
  int index = 0, count = 1;
  std::string scene_digest;      // digest of the scene and settings the shard was baked from
  int total_rdms = 0;            // RDMs of the whole scene
  LightingFingerprint lighting;  // the merged atlas's index.json "lighting"; empty: unknown
};

// Version 2 records each RDM's skipped faces, which the compact atlas leaves out.
constexpr int kShardVersion = 2;

// contentHashHex of the canonical scene JSON (settings included).
std::string sceneDigest(const Scene& scene);

// One RDM at a time from `rdms`.
Status writeShard(const std::string& dir, const ShardManifest& manifest, const RdmSource& rdms);
Status writeShard(const std::string& dir, const ShardManifest& manifest,
                  const std::vector<RdmData>& rdms);
// One RDM of a shard: its texels stay in `path` until read.
struct ShardRdm {
  RdmId id;
  std::array<bool, 6> skipped{};
  std::string path;
};
struct LoadedShard {
  ShardManifest manifest;
  std::vector<ShardRdm> rdms;
};
// Reads shard.json; the RDM images are read when a ShardSet visits them.
Expected<LoadedShard> readShard(const std::string& dir);

// The RDMs of a complete set of shards, read one at a time (a merge holds one page and one
// RDM, whatever the world's size). A missing, unreadable or wrongly sized RDM image fails
// the read naming its file.
class ShardSet final : public RdmSource {
 public:
  explicit ShardSet(std::vector<ShardRdm> rdms) : rdms_(std::move(rdms)) {}
  std::vector<RdmId> ids() const override;
  Expected<std::vector<RdmDigest>> digests() const override;
  Status visit(size_t i, const std::function<void(const RdmData&)>& use) const override;
  // Skipped faces without reading texels.
  const std::vector<ShardRdm>& rdms() const { return rdms_; }

 private:
  std::vector<ShardRdm> rdms_;
};

// Checks the shards form one complete set (same digest and count, every index once, every
// RDM present) and returns all their RDMs.
Expected<ShardSet> mergeShards(std::vector<LoadedShard> shards);

}  // namespace rdm
