#include <cstdio>

#include "cli_app.h"
#include "commands.h"
#include "output_check.h"
#include "rdm/scene/scene.h"
#include "scene_options.h"

namespace rdm::cli {

// `rdm scene --scene NAME -o FILE` exports a built-in scene; `rdm scene FILE` validates one.
int cmdScene(const Args& args) {
  std::string file, name, out;
  bool list = false;
  VerbApp app("scene",
              "Export a built-in scene as JSON (to stdout or -o FILE), validate a "
              "scene file, or list the built-in scenes.");
  app.add_option("SCENE", file, "scene JSON file to validate");
  app.add_option("--scene", name, "built-in scene to export");
  app.add_option("-o,--output", out, "write the scene JSON here")->default_str("stdout");
  app.add_flag("--list", list, "list the built-in scenes");
  if (auto code = parseArgs(app, args)) return *code;
  if (list) {
    for (const std::string& n : builtinSceneNames()) std::printf("%s\n", n.c_str());
    return 0;
  }
  const std::string source = name.empty() ? file : name;
  if (source.empty()) return fail("scene", "no scene given (SCENE.json or --scene NAME)", 2);
  if (!out.empty()) {
    if (Status s = checkOutputFile(out); !s) return fail("scene", s.message());
  }
  auto scene = loadSceneArgument(source);
  if (!scene) return fail("scene", scene.error());
  if (out.empty()) {
    if (!name.empty()) {
      std::fputs(sceneToJson(*scene).c_str(), stdout);
    } else {
      std::printf("%s: valid (%zu placements, %zu blocks)\n", source.c_str(),
                  scene->placements.size(), scene->blocks.size());
    }
    return 0;
  }
  if (Status s = saveSceneFile(out, *scene); !s) return fail("scene", s.message());
  return 0;
}

}  // namespace rdm::cli
