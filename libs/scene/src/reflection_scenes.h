// Built-in scenes made for the cases where a block-centred RDM reflects the wrong thing
// (issue 39; docs/results.md section 1g), internal to the scene part.
#pragma once

#include "rdm/scene/scene.h"

namespace rdm {

Scene mirrorLampScene();
Scene mirrorCorridorScene();
Scene mirrorRowScene();
Scene darkPiecesScene();

}  // namespace rdm
