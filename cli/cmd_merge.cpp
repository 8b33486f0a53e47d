#include <cstdio>
#include <filesystem>
#include <optional>

#include "cli_app.h"
#include "commands.h"
#include "output_check.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/slot_sets_file.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/shard.h"

namespace rdm::cli {
namespace {

// The shards' face_light.bin files as one (baked with --face-light), none when no shard has
// one; a set where only some have one is refused, naming a shard without.
Expected<std::optional<FaceLight>> mergedFaceLight(const std::vector<std::string>& dirs,
                                                   const std::vector<RdmId>& rdms) {
  std::vector<FaceLight> parts;
  std::string without;
  for (const std::string& dir : dirs) {
    const std::string path = dir + "/" + kFaceLightFile;
    if (std::error_code ec; !std::filesystem::exists(path, ec)) {
      without = dir;
      continue;
    }
    auto light = readFaceLight(path);
    if (!light) return light.status();
    parts.push_back(std::move(*light));
  }
  if (parts.empty()) return std::optional<FaceLight>();
  if (!without.empty())
    return Status::invalid(kFaceLightFile, "shard " + without +
                                               " has no face_light.bin while others do: bake "
                                               "every shard with the same --face-light");
  auto merged = mergeFaceLights(std::move(parts), rdms);
  if (!merged) return merged.status();
  return std::optional<FaceLight>(std::move(*merged));
}

// The shards' rdms.bin files as one; none when no shard has one (baked before 2026-12-06); a
// set where only some have one is refused, naming a shard without.
Expected<std::optional<std::vector<RdmRecord>>> mergedSlotSets(
    const std::vector<std::string>& dirs) {
  std::vector<RdmRecord> all;
  std::string with, without;
  for (const std::string& dir : dirs) {
    auto records = readSlotSetsFile(dir);
    if (!records && records.status().code() == StatusCode::kNotFound) {
      without = dir;
      continue;
    }
    if (!records) return records.status();
    with = dir;
    for (auto& [key, r] : *records) all.push_back(std::move(r));
  }
  if (with.empty()) return std::optional<std::vector<RdmRecord>>();
  if (!without.empty())
    return Status::invalid(kRdmRecordsFile, "shard " + without + " has no " + kRdmRecordsFile +
                                                " while " + with +
                                                " has: bake every shard with "
                                                "the same rdm version");
  return std::optional<std::vector<RdmRecord>>(std::move(all));
}

// Reads the shards in `dirs` and writes their atlas (and face light) into `out`.
int mergeInto(const std::vector<std::string>& dirs, const std::string& out) {
  std::vector<LoadedShard> shards;
  for (const std::string& dir : dirs) {
    auto shard = readShard(dir);
    if (!shard) return fail("merge", shard.error());
    shards.push_back(std::move(*shard));
  }
  const size_t shard_count = shards.size();
  // mergeShards refuses shards of different scenes, so the first one's lighting is all's.
  const LightingFingerprint lighting =
      shards.empty() ? LightingFingerprint() : shards[0].manifest.lighting;
  auto rdms = mergeShards(std::move(shards));
  if (!rdms) return fail("merge", rdms.error());
  const std::vector<RdmId> ids = rdms->ids();
  std::vector<RdmData> faces;  // skipped faces only: packing reads no texels
  for (const ShardRdm& r : rdms->rdms()) faces.push_back({r.id, {}, {}, r.skipped});
  AtlasLayout layout = packCanonical(ids, storedFacesOf(faces));
  layout.lighting = lighting;
  auto light = mergedFaceLight(dirs, ids);
  if (!light) return fail("merge", light.error());
  auto slot_sets = mergedSlotSets(dirs);
  if (!slot_sets) return fail("merge", slot_sets.error());
  if (Status s = writeAtlasOutputs(out, layout, *rdms); !s) return fail("merge", s.message());
  if (*slot_sets) {
    if (Status s = writeSlotSetsFile(out, std::move(**slot_sets)); !s)
      return fail("merge", s.message());
  }
  if (*light) {
    if (Status s = writeFaceLight(out + "/" + kFaceLightFile, **light); !s)
      return fail("merge", s.message());
    std::printf("merged the face light of %zu slots\n", (*light)->slots.size());
  }
  std::printf("merged %zu shards, %zu RDMs, face tiles cover %.2f %% of the atlas, into %s\n",
              shard_count, ids.size(), 100.0 * layout.occupancy(), out.c_str());
  return 0;
}

}  // namespace

int cmdMerge(const Args& args) {
  std::vector<std::string> dirs;
  std::string out;
  VerbApp app(
      "merge",
      "Merge the shard outputs of `rdm bake --shard` into one atlas (and one face_light.bin when "
      "the shards were baked with --face-light).");
  app.add_option("SHARD_DIR", dirs, "shard output directories (all N of them)")->required();
  app.add_option("-o,--output", out, "output directory (checked before the shards are read)")
      ->required();
  if (auto code = parseArgs(app, args)) return *code;
  bool created = false;
  if (Status s = prepareOutputDirectory(out, created); !s) return fail("merge", s.message());
  const int code = mergeInto(dirs, out);
  if (code != 0 && created) removeIfEmpty(out);
  return code;
}

}  // namespace rdm::cli
