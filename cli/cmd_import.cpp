#include <cstdio>

#include "args.h"
#include "commands.h"
#include "rdm/file_util.h"
#include "rdm/vox_import.h"

namespace rdm::cli {

// `rdm import MODEL.vox -o SCENE.json [--roughness R] [--metallic M]`
int cmdImport(const Args& args) {
  ArgParser parser({"-o", "--output", "--roughness", "--metallic"}, {"--help"});
  std::string e = parser.parse(args);
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (!e.empty() || parser.flag("--help") || !out || parser.positionals().size() != 1) {
    std::fprintf(
        stderr,
        "%susage: rdm import MODEL.vox -o SCENE.json [--roughness 0..7] [--metallic 0..3]\n",
        e.empty() ? "" : ("rdm import: " + e + "\n").c_str());
    return parser.flag("--help") ? 0 : 2;
  }
  std::string error;
  VoxImportOptions options;
  options.roughness = int(parser.integer("--roughness", error).value_or(7));
  options.metallic = int(parser.integer("--metallic", error).value_or(0));
  if (options.roughness < 0 || options.roughness > 7 || options.metallic < 0 ||
      options.metallic > 3) {
    error = "--roughness must be 0..7 and --metallic 0..3";
  }
  if (!error.empty()) return std::fprintf(stderr, "rdm import: %s\n", error.c_str()), 2;
  const std::string& path = parser.positionals()[0];
  auto bytes = readFileToString(path);
  if (!bytes) return std::fprintf(stderr, "rdm import: %s\n", bytes.error().c_str()), 1;
  auto scene = importVox(*bytes, options);
  if (!scene)
    return std::fprintf(stderr, "rdm import: %s: %s\n", path.c_str(), scene.error().c_str()), 1;
  if (Status s = saveSceneFile(*out, *scene); !s)
    return std::fprintf(stderr, "rdm import: %s\n", s.message().c_str()), 1;
  std::printf("imported %zu blocks, %zu colours into %s\n", scene->blocks.size(),
              scene->palette.size(), out->c_str());
  return 0;
}

}  // namespace rdm::cli
