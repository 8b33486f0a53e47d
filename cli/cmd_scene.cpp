#include <cstdio>

#include "args.h"
#include "commands.h"
#include "rdm/scene.h"

namespace rdm::cli {

// `rdm scene --scene NAME -o FILE` exports a built-in scene; `rdm scene FILE` validates one.
int cmdScene(const Args& args) {
  ArgParser parser({"--scene", "-o", "--output"}, {"--help", "--list"});
  std::string e = parser.parse(args);
  if (!e.empty() || parser.flag("--help")) {
    std::fprintf(stderr, "%susage: rdm scene --list | --scene NAME [-o FILE] | SCENE.json\n",
                 e.empty() ? "" : ("rdm scene: " + e + "\n").c_str());
    return e.empty() ? 0 : 2;
  }
  if (parser.flag("--list")) {
    for (const std::string& name : builtinSceneNames()) std::printf("%s\n", name.c_str());
    return 0;
  }
  std::string source =
      parser.value("--scene").value_or(parser.positionals().empty() ? "" : parser.positionals()[0]);
  if (source.empty()) return std::fprintf(stderr, "rdm scene: no scene given\n"), 2;
  auto scene = loadSceneByNameOrPath(source);
  if (!scene) return std::fprintf(stderr, "rdm scene: %s\n", scene.error().c_str()), 1;
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (!out) {
    if (parser.value("--scene")) {
      std::printf("%s\n", sceneToJson(*scene).c_str());
    } else {
      std::printf("%s: valid (%zu placements, %zu blocks)\n", source.c_str(),
                  scene->placements.size(), scene->blocks.size());
    }
    return 0;
  }
  if (Status s = saveSceneFile(*out, *scene); !s)
    return std::fprintf(stderr, "rdm scene: %s\n", s.message().c_str()), 1;
  return 0;
}

}  // namespace rdm::cli
