// C++ access to the host/device headers: the conventions of shaders/shared/rdm_shared.h and
// the float voxel walk of shaders/shared/rdm_walk.h.
#pragma once

#include "shared/rdm_shared.h"
#include "shared/rdm_walk.h"
