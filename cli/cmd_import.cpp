#include <cstdio>
#include <string>

#include "cli_app.h"
#include "commands.h"
#include "number_checks.h"
#include "output_check.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/vox_import.h"

namespace rdm::cli {
namespace {

std::string plural(size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

void printReport(const VoxImportReport& r, const Scene& scene, const std::string& out) {
  std::printf(
      "imported %s, %s%s: %llu voxels in %s, %s (%s)\n",
      plural(size_t(r.models), "model", "models").c_str(),
      plural(size_t(r.instances), "placed shape", "placed shapes").c_str(),
      r.scene_graph ? " from the scene graph" : "", (unsigned long long)r.voxels,
      plural(scene.blocks.size(), "block", "blocks").c_str(),
      plural(scene.palette.size() - (r.ground_voxels > 0 ? 1 : 0), "colour", "colours").c_str(),
      r.default_palette ? "MagicaVoxel's default palette" : "the file's palette");
  if (r.frames > 1)
    std::printf("frames:   %d animation frames; imported frame %d (--frame to choose)\n", r.frames,
                r.frame);
  std::printf("grid:     %d x %d x %d slots (Y up)\n", scene.size[0], scene.size[1], scene.size[2]);
  if (r.ground_voxels > 0)
    std::printf(
        "ground:   %llu voxels, light grey diffuse, one voxel under the model, %d wider "
        "on each side\n",
        (unsigned long long)r.ground_voxels, kGroundMargin);
  constexpr size_t kShown = 12;
  for (size_t i = 0; i < r.mapped.size() && i < kShown; ++i)
    std::printf("mapped:   %s\n", r.mapped[i].c_str());
  if (r.mapped.size() > kShown)
    std::printf("mapped:   ... %zu more colours\n", r.mapped.size() - kShown);
  if (r.mapped.empty())
    std::printf(r.materials > 0
                    ? "mapped:   %d MATL materials, diffuse on every colour used: the defaults\n"
                    : "mapped:   no MATL materials: every colour uses the defaults\n",
                r.materials);
  if (scene.emission_scale != 1.0)
    std::printf("mapped:   emitters' _flux -> emission_scale %.3g\n", scene.emission_scale);
  for (const std::string& l : r.lights) std::printf("light:    %s\n", l.c_str());
  for (const std::string& c : r.cameras) std::printf("camera:   %s\n", c.c_str());
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
              "by the scene graph at one animation frame, the file's sun, sky and cameras "
              "plus standard views (front, back, left, right, top, iso), MATL materials mapped to "
              "roughness, metallic and "
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
  app.add_option("--frame", options.frame,
                 "animation frame to import (nTRN/nSHP keyframes, or PACK model), from 0")
      ->check(wholeNumberIn(0, 65535));
  app.add_option("--layers", options.layers,
                 "layers (LAYR name or index, comma-separated) to include even when hidden")
      ->delimiter(',');
  app.add_flag("--ground", options.ground,
               "add a one-voxel light grey floor under the model's footprint, 4 voxels wider "
               "on each side");
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
