#include "scene_options.h"

namespace rdm::cli {

Expected<Scene> sceneFromArgs(const ArgParser& parser) {
  std::string source;
  if (auto name = parser.value("--scene")) {
    source = *name;
  } else if (!parser.positionals().empty()) {
    source = parser.positionals().front();
  } else {
    return Status::error(
        "no scene given: pass SCENE.json or --scene NAME (chess, island, furnace)");
  }
  auto scene = loadSceneByNameOrPath(source);
  if (!scene) return scene;
  std::string error;
  if (auto v = parser.integer("--spp", error)) scene->bake.spp = int(*v);
  if (auto v = parser.integer("--max-hemisphere", error)) scene->bake.max_hemisphere = int(*v);
  if (auto v = parser.integer("--max-bounces", error)) scene->bake.max_bounces = int(*v);
  if (auto v = parser.integer("--seed", error)) scene->bake.seed = uint32_t(*v);
  if (!error.empty()) return Status::error(error);
  if (Status s = validateScene(*scene); !s)
    return Status::error("invalid settings: " + s.message());
  return scene;
}

}  // namespace rdm::cli
