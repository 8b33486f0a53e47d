// Shard outputs of `rdm bake --shard I/N` and their merge (deploy issue): a shard directory
// holds shard.json and one RGBZ EXR per RDM; merging packs canonically, so the merged atlas
// equals a one-process bake byte for byte.
#pragma once

#include <string>
#include <vector>

#include "rdm/bake.h"
#include "rdm/status.h"

namespace rdm {

struct ShardManifest {
  int index = 0, count = 1;
  std::string scene_digest;  // digest of the scene and settings the shard was baked from
  int total_rdms = 0;        // RDMs of the whole scene
};

// Version 2 records each RDM's skipped faces, which the compact atlas leaves out.
constexpr int kShardVersion = 2;

// contentHashHex of the canonical scene JSON (settings included).
std::string sceneDigest(const Scene& scene);

Status writeShard(const std::string& dir, const ShardManifest& manifest,
                  const std::vector<RdmData>& rdms);
struct LoadedShard {
  ShardManifest manifest;
  std::vector<RdmData> rdms;
};
Expected<LoadedShard> readShard(const std::string& dir);
// Checks the shards form one complete set (same digest and count, every index once, every
// RDM present) and returns all their RDMs.
Expected<std::vector<RdmData>> mergeShards(const std::vector<LoadedShard>& shards);

}  // namespace rdm
