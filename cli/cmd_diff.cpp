#include <cstdio>

#include "atlas_input.h"
#include "cli_app.h"
#include "commands.h"
#include "rdm/atlas/atlas.h"

namespace rdm::cli {

int cmdDiff(const Args& args) {
  std::string a_dir, b_dir;
  VerbApp app("diff",
              "Compare two atlases RDM by RDM, wherever each placed them: exit 0 when they hold "
              "the same RDMs with bit-identical texels (R, G, B and depth), 1 when not. An "
              "incremental job's atlas against a one-shot bake of the same scene, say.");
  app.add_option("A", a_dir, "atlas directory (index.json and atlas pages)")->required();
  app.add_option("B", b_dir, "the other atlas directory")->required();
  if (auto code = parseArgs(app, args)) return *code;
  for (const std::string& dir : {a_dir, b_dir}) {
    if (Status s = checkAtlasDirectory(dir); !s) return fail("diff", s.message());
  }
  auto a = readAtlasOutputs(a_dir);
  if (!a) return fail("diff", a.error());
  auto b = readAtlasOutputs(b_dir);
  if (!b) return fail("diff", b.error());
  const std::vector<RdmId> differ = differingRdms(*a, *b);
  if (differ.empty()) {
    std::printf("identical: %zu RDMs\n", a->layout.entries.size());
    return 0;
  }
  std::printf("%zu RDM(s) differ (of %zu in %s, %zu in %s); first: slot (%d, %d, %d) level %d\n",
              differ.size(), a->layout.entries.size(), a_dir.c_str(), b->layout.entries.size(),
              b_dir.c_str(), differ[0].slot.x, differ[0].slot.y, differ[0].slot.z, differ[0].level);
  return 1;
}

}  // namespace rdm::cli
