// The file's light (vox_lights.cpp): MagicaVoxel's sun and sky, from its render objects.
#pragma once

#include <string>
#include <vector>

#include "rdm/scene/scene.h"
#include "vox_parse.h"

namespace rdm::vox {

// Sets the scene's sun, sky and ambient: the defaults of docs/import.md, replaced by the
// file's sun (rOBJ `_type _inf`, or rLIT) and uniform sky (rOBJ `_uni`, or rAIR) where present.
// One line per mapping goes to `mapped`, one per dropped render setting to `dropped`.
void mapLights(const VoxFile& f, Scene& scene, std::vector<std::string>& mapped,
               std::vector<std::string>& dropped);

}  // namespace rdm::vox
