// Atlas layout of an incremental bake (docs/spec.md section 4): the base's rects are kept and new
// RDMs go into free space.
#pragma once

#include <vector>

#include "rdm/atlas.h"

namespace rdm {

// Lays out `rdms` (any order). An RDM found in `base` with the same slot, level and size
// keeps its page and rect; every other RDM is placed, in canonical order, at the first free
// position of its own alignment (x a multiple of 2S, y of 3S) on an existing page, scanning
// pages in order and rows top-down; a page may grow in height up to kMaxPageSize, and a
// new page (as wide as page 0, at least 2S) is opened when none has room. Rects of base RDMs
// missing from `rdms` become free space. With an empty base this is packCanonical(rdms).
// Entries come out in canonical order; scene_version is copied from `base`.
AtlasLayout packIncremental(const AtlasLayout& base, const std::vector<RdmId>& rdms);

}  // namespace rdm
