#include "scene_options.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

namespace rdm::cli {
namespace {

std::string builtinList() {
  std::string list;
  for (const std::string& name : builtinSceneNames()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string suggestion(const std::string& source) {
  for (const std::string& name : builtinSceneNames()) {
    if (editDistance(source, name) <= 2) return " Did you mean '" + name + "'?";
  }
  return {};
}

}  // namespace

void addSceneOptions(CLI::App& app, SceneArgs& s, const std::string& spp_help) {
  app.add_option("SCENE", s.file, "scene JSON file (or use --scene)");
  app.add_option("--scene", s.name, "built-in scene (" + builtinList() + ") or scene file");
  if (!spp_help.empty())
    s.spp_option = app.add_option("--spp", s.spp, spp_help)->default_str("scene's bake.spp");
  s.hemisphere_option =
      app.add_option("--max-hemisphere", s.max_hemisphere, "largest hemisphere size S of an RDM")
          ->default_str("scene's bake.max_hemisphere");
  s.bounces_option = app.add_option("--max-bounces", s.max_bounces, "path length limit")
                         ->default_str("scene's bake.max_bounces");
  s.seed_option = app.add_option("--seed", s.seed, "random seed")->default_str("scene's bake.seed");
}

Expected<Scene> loadSceneArgument(const std::string& source) {
  const std::vector<std::string> names = builtinSceneNames();
  if (std::find(names.begin(), names.end(), source) != names.end()) return builtinScene(source);
  std::ifstream probe(source, std::ios::binary);
  if (!probe) {
    const std::string reason = std::strerror(errno);
    return Status::error("'" + source + "' is neither a built-in scene (" + builtinList() +
                         ") nor a readable scene file (" + reason + ")." + suggestion(source));
  }
  return loadSceneFile(source);
}

Expected<Scene> sceneFromArgs(const SceneArgs& args) {
  if (!args.name.empty() && !args.file.empty())
    return Status::error("give either SCENE.json or --scene NAME, not both");
  const std::string source = args.name.empty() ? args.file : args.name;
  if (source.empty())
    return Status::error("no scene given: pass SCENE.json or --scene NAME (" + builtinList() + ")");
  auto scene = loadSceneArgument(source);
  if (!scene) return scene;
  if (args.spp_option && *args.spp_option) scene->bake.spp = args.spp;
  if (*args.hemisphere_option) scene->bake.max_hemisphere = args.max_hemisphere;
  if (*args.bounces_option) scene->bake.max_bounces = args.max_bounces;
  if (*args.seed_option) scene->bake.seed = args.seed;
  if (Status s = validateScene(*scene); !s)
    return Status::error("invalid settings: " + s.message());
  return scene;
}

}  // namespace rdm::cli
