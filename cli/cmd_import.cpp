#include <cstdio>

#include "cli_app.h"
#include "commands.h"
#include "number_checks.h"
#include "output_check.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/vox_import.h"

namespace rdm::cli {
namespace {

void printReport(const VoxImportReport& r, const Scene& scene, const std::string& out) {
  std::printf(
      "imported %d of %d model(s) as %d placed shape(s)%s: %llu voxels in %zu blocks, "
      "%zu colours (%s)\n",
      r.instances, r.models, r.instances, r.scene_graph ? " from the scene graph" : "",
      (unsigned long long)r.voxels, scene.blocks.size(), scene.palette.size(),
      r.default_palette ? "MagicaVoxel's default palette" : "the file's palette");
  std::printf("grid:     %d x %d x %d slots (Y up)\n", scene.size[0], scene.size[1], scene.size[2]);
  constexpr size_t kShown = 12;
  for (size_t i = 0; i < r.mapped.size() && i < kShown; ++i)
    std::printf("mapped:   %s\n", r.mapped[i].c_str());
  if (r.mapped.size() > kShown) std::printf("mapped:   ... %zu more\n", r.mapped.size() - kShown);
  if (r.mapped.empty())
    std::printf("mapped:   no MATL materials: every colour uses the defaults\n");
  if (scene.emission_scale != 1.0)
    std::printf("mapped:   emitters' _flux -> emission_scale %.3g\n", scene.emission_scale);
  for (const std::string& d : r.dropped) std::printf("dropped:  %s\n", d.c_str());
  for (const std::string& c : r.chosen) std::printf("chosen:   %s\n", c.c_str());
  std::printf("wrote %s\n", out.c_str());
}

}  // namespace

int cmdImport(const Args& args) {
  std::string in, out;
  VoxImportOptions options;
  int roughness = -1;
  VerbApp app("import",
              "Import a MagicaVoxel .vox file as a scene JSON: every model placed "
              "by the scene graph, MATL materials mapped to roughness, metallic and "
              "emission, with a report of what was mapped and what was dropped. The "
              "scene's bake settings (max_hemisphere, spp, face_light_spp) are chosen "
              "from the model's size and materials; the report says why.");
  app.add_option("MODEL", in, "MagicaVoxel .vox file")->required();
  app.add_option("-o,--output", out, "scene JSON to write")->required();
  CLI::Option* roughness_option =
      app.add_option("--roughness", roughness,
                     "roughness level 0..7 of colours without a material (or _diffuse, "
                     "_emit) and of _metal without _rough; below 7 each of their blocks "
                     "gets a glossy RDM too")
          ->check(wholeNumberIn(0, 7))
          ->default_str("7 (Lambert), 5 for such metals");
  app.add_option("--metallic", options.metallic, "metallic level 0..3 of those colours")
      ->check(wholeNumberIn(0, 3));
  if (auto code = parseArgs(app, args)) return *code;
  if (roughness_option->count() > 0) options.roughness = roughness;
  if (Status s = checkOutputFile(out); !s) return fail("import", s.message());
  auto bytes = readFileToString(in);
  if (!bytes) return fail("import", bytes.error());
  VoxImportReport report;
  auto scene = importVox(*bytes, options, &report);
  if (!scene) return fail("import", in + ": " + scene.error());
  if (Status s = saveSceneFile(out, *scene); !s) return fail("import", s.message());
  printReport(report, *scene, out);
  return 0;
}

}  // namespace rdm::cli
