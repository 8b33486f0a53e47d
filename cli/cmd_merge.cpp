#include <cstdio>

#include "args.h"
#include "commands.h"
#include "rdm/atlas.h"
#include "rdm/shard.h"

namespace rdm::cli {

int cmdMerge(const Args& args) {
  ArgParser parser({"-o", "--output"}, {"--help"});
  std::string e = parser.parse(args);
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (!e.empty() || parser.flag("--help") || !out || parser.positionals().empty()) {
    std::fprintf(stderr, "%susage: rdm merge SHARD_DIR... -o DIR\n",
                 e.empty() ? "" : ("rdm merge: " + e + "\n").c_str());
    return parser.flag("--help") ? 0 : 2;
  }
  std::vector<LoadedShard> shards;
  for (const std::string& dir : parser.positionals()) {
    auto shard = readShard(dir);
    if (!shard) return std::fprintf(stderr, "rdm merge: %s\n", shard.error().c_str()), 1;
    shards.push_back(std::move(*shard));
  }
  auto rdms = mergeShards(shards);
  if (!rdms) return std::fprintf(stderr, "rdm merge: %s\n", rdms.error().c_str()), 1;
  std::vector<RdmId> ids;
  for (const RdmData& d : *rdms) ids.push_back(d.id);
  AtlasLayout layout = packCanonical(ids);
  if (Status s = writeAtlasOutputs(*out, layout, *rdms); !s)
    return std::fprintf(stderr, "rdm merge: %s\n", s.message().c_str()), 1;
  std::printf("merged %zu shards, %zu RDMs, occupancy %.2f %% into %s\n", shards.size(),
              rdms->size(), 100.0 * layout.occupancy(), out->c_str());
  return 0;
}

}  // namespace rdm::cli
