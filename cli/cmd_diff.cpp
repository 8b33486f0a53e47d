#include <cstdio>

#include "atlas_input.h"
#include "cli_app.h"
#include "commands.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_compare.h"

namespace rdm::cli {
namespace {

// The --error table: per level, A's error against B and both atlases' border differences.
int printErrors(const LoadedAtlas& a, const LoadedAtlas& b) {
  const LevelSums error = atlasError(a, b);
  const LevelSums border_a = borderDifference(a), border_b = borderDifference(b);
  std::printf("level  texels    error(A vs B)  border(A)  border(B)\n");
  LuminanceSums all, all_a, all_b;
  for (size_t level = 0; level < error.size(); ++level) {
    if (error[level].texels == 0) continue;
    std::printf("%5zu  %8zu  %13.5f  %9.5f  %9.5f\n", level, error[level].texels,
                error[level].relative(), border_a[level].relative(), border_b[level].relative());
    for (auto [sum, part] :
         {std::pair{&all, &error[level]}, {&all_a, &border_a[level]}, {&all_b, &border_b[level]}}) {
      sum->difference += part->difference, sum->value += part->value, sum->texels += part->texels;
    }
  }
  std::printf("  all  %8zu  %13.5f  %9.5f  %9.5f\n", all.texels, all.relative(), all_a.relative(),
              all_b.relative());
  return 0;
}

}  // namespace

int cmdDiff(const Args& args) {
  std::string a_dir, b_dir;
  VerbApp app("diff",
              "Compare two atlases RDM by RDM, wherever each placed them: exit 0 when they hold "
              "the same RDMs with bit-identical texels (R, G, B and depth), 1 when not. An "
              "incremental job's atlas against a one-shot bake of the same scene, say.");
  app.add_option("A", a_dir, "atlas directory (index.json and atlas pages)")->required();
  app.add_option("B", b_dir, "the other atlas directory")->required();
  bool error = false;
  app.add_flag("--error", error,
               "measure instead of compare: per level, A's relative error against B (a "
               "reference bake) and each atlas's block-border difference (docs/denoise.md)");
  if (auto code = parseArgs(app, args)) return *code;
  for (const std::string& dir : {a_dir, b_dir}) {
    if (Status s = checkAtlasDirectory(dir); !s) return fail("diff", s.message());
  }
  auto a = readAtlasOutputs(a_dir);
  if (!a) return fail("diff", a.error());
  auto b = readAtlasOutputs(b_dir);
  if (!b) return fail("diff", b.error());
  if (error) return printErrors(*a, *b);
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
