#include <cstdio>

#include "cli_app.h"
#include "commands.h"
#include "rdm/atlas.h"
#include "rdm/shard.h"

namespace rdm::cli {

int cmdMerge(const Args& args) {
  std::vector<std::string> dirs;
  std::string out;
  VerbApp app("merge", "Merge the shard outputs of `rdm bake --shard` into one atlas.");
  app.add_option("SHARD_DIR", dirs, "shard output directories (all N of them)")->required();
  app.add_option("-o,--output", out, "output directory")->required();
  if (auto code = parseArgs(app, args)) return *code;
  std::vector<LoadedShard> shards;
  for (const std::string& dir : dirs) {
    auto shard = readShard(dir);
    if (!shard) return fail("merge", shard.error());
    shards.push_back(std::move(*shard));
  }
  auto rdms = mergeShards(shards);
  if (!rdms) return fail("merge", rdms.error());
  std::vector<RdmId> ids;
  for (const RdmData& d : *rdms) ids.push_back(d.id);
  AtlasLayout layout = packCanonical(ids, storedFacesOf(*rdms));
  if (Status s = writeAtlasOutputs(out, layout, *rdms); !s) return fail("merge", s.message());
  std::printf("merged %zu shards, %zu RDMs, face tiles cover %.2f %% of the atlas, into %s\n",
              shards.size(), rdms->size(), 100.0 * layout.occupancy(), out.c_str());
  return 0;
}

}  // namespace rdm::cli
