// C++ access to the host/device conventions header shaders/shared/rdm_shared.h.
#pragma once

#include "shared/rdm_shared.h"
