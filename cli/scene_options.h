// Scene selection and bake-setting overrides shared by the verbs that bake or render.
#pragma once

#include <string>

#include "args.h"
#include "rdm/scene.h"
#include "rdm/status.h"

namespace rdm::cli {

inline const std::set<std::string> kSceneValueOptions = {
    "--scene", "--spp", "--max-hemisphere", "--max-bounces", "--seed", "--threads"};

// The scene named by --scene or the first positional, with --spp, --max-hemisphere,
// --max-bounces and --seed applied and validated.
Expected<Scene> sceneFromArgs(const ArgParser& parser);

}  // namespace rdm::cli
