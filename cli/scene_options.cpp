#include "scene_options.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "number_checks.h"
#include "rdm/scene/bake_settings_json.h"

namespace rdm::cli {
namespace {

std::string builtinList() {
  return builtinSceneList();
}

// The check of the bake setting `key`: the range a scene file may give it, so an override is
// refused as a usage error naming the option.
CLI::Validator settingCheck(const std::string& key) {
  for (const BakeSettingRange& r : bakeSettingRanges()) {
    if (r.key == key) return r.power_of_two ? powerOfTwoIn(r.lo, r.hi) : wholeNumberIn(r.lo, r.hi);
  }
  RDM_CHECK(false && "not a bake setting");
  return {};
}

}  // namespace

void addSceneOptions(CLI::App& app, SceneArgs& s, const std::string& spp_help) {
  app.add_option("SCENE", s.file, "scene JSON file (or use --scene)");
  app.add_option("--scene", s.name, "built-in scene (" + builtinList() + ") or scene file");
  if (!spp_help.empty()) {
    s.spp_option = app.add_option("--spp", s.spp, spp_help)
                       ->check(settingCheck("spp"))
                       ->default_str("scene's bake.spp");
  }
  s.hemisphere_option =
      app.add_option("--max-hemisphere", s.max_hemisphere, "largest hemisphere size S of an RDM")
          ->check(settingCheck("max_hemisphere"))
          ->default_str("scene's bake.max_hemisphere");
  s.bounces_option = app.add_option("--max-bounces", s.max_bounces, "path length limit")
                         ->check(settingCheck("max_bounces"))
                         ->default_str("scene's bake.max_bounces");
  s.seed_option = app.add_option("--seed", s.seed, "random seed")
                      ->check(settingCheck("seed"))
                      ->default_str("scene's bake.seed");
  s.estimator_option =
      app.add_option("--estimator", s.estimator,
                     "prefiltered (one radiance map per face, levels derived from it) or naive "
                     "(every level path traced on its own; docs/spec.md section 3.1)")
          ->check(CLI::IsMember({"naive", "prefiltered"}))
          ->default_str("scene's bake.estimator");
}

Expected<Scene> loadSceneArgument(const std::string& source) {
  return loadSceneByNameOrPath(source);
}

Status checkSceneArgs(const SceneArgs& args) {
  if (!args.name.empty() && !args.file.empty())
    return Status::error("give either SCENE.json or --scene NAME, not both");
  if (args.name.empty() && args.file.empty())
    return Status::error("no scene given: pass SCENE.json or --scene NAME (" + builtinList() + ")");
  return {};
}

Expected<Scene> sceneFromArgs(const SceneArgs& args) {
  if (Status s = checkSceneArgs(args); !s) return s;
  const std::string source = args.name.empty() ? args.file : args.name;
  auto scene = loadSceneArgument(source);
  if (!scene) return scene;
  if (args.spp_option && *args.spp_option) scene->bake.spp = args.spp;
  if (*args.hemisphere_option) scene->bake.max_hemisphere = args.max_hemisphere;
  if (*args.bounces_option) scene->bake.max_bounces = args.max_bounces;
  if (*args.seed_option) scene->bake.seed = args.seed;
  if (*args.estimator_option) {
    auto estimator = parseEstimator(args.estimator);
    if (!estimator) return Status::error("invalid settings: --estimator: " + estimator.error());
    scene->bake.estimator = *estimator;
  }
  if (Status s = validateScene(*scene); !s)
    return Status::error("invalid settings: " + s.message());
  return scene;
}

}  // namespace rdm::cli
