// Scene selection and bake-setting overrides shared by the verbs that bake or render.
#pragma once

#include <string>

#include "cli_app.h"
#include "rdm/base/status.h"
#include "rdm/scene/scene.h"

namespace rdm::cli {

// --spp, --max-hemisphere, --max-bounces, --seed and --estimator override the scene's own bake
// settings only when given.
struct SceneArgs {
  std::string file, name;
  int spp = 0, max_hemisphere = 0, max_bounces = 0;
  uint32_t seed = 0;
  std::string estimator;
  CLI::Option *spp_option = nullptr, *hemisphere_option = nullptr, *bounces_option = nullptr,
              *seed_option = nullptr, *estimator_option = nullptr;
};

// Adds the positional SCENE.json, --scene NAME and the overrides; --spp only when
// `spp_help` is non-empty (rdm render has its own).
void addSceneOptions(CLI::App& app, SceneArgs& scene, const std::string& spp_help);

// The usage errors of the scene arguments (exit code 2): no scene, or both SCENE.json and
// --scene. The overrides' ranges are checked when the options are parsed.
[[nodiscard]] Status checkSceneArgs(const SceneArgs& args);

// The scene named by --scene or the positional, with the overrides applied and validated.
Expected<Scene> sceneFromArgs(const SceneArgs& args);

// A built-in scene by name, else a scene file; a source that is neither is refused with the
// list of built-in names and the reason the file could not be read.
Expected<Scene> loadSceneArgument(const std::string& source);

}  // namespace rdm::cli
