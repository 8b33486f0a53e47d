// Atlas layout of an incremental bake (docs/spec.md section 4): the base's face tiles are kept
// and new tiles go into free space.
#pragma once

#include <vector>

#include "rdm/atlas/atlas.h"

namespace rdm {

// Lays out `rdms` (any order). A stored face of an RDM found in `base` with the same slot,
// level and size, and stored there too, keeps its page and tile; every other stored face is
// placed, in canonical order (RDM, then face), at the first free position of its own
// alignment (x and y multiples of S) on an existing page, scanning pages in order and rows
// top-down; a page may grow in height up to kPackedPageSize, and a new page (as wide as page 0,
// at least S) is opened when none has room. Tiles of `base` no face of `rdms` keeps become
// free space. With an empty base this is packCanonical(rdms, stored). Entries come out in
// canonical order; scene_version is copied from `base`. The result's `radiance` is `format`;
// with kBc6h the positions are multiples of max(S, kBc6hTileAlign) (blockAligned), and a base
// that is not bc6h keeps no tile (packCanonical).
AtlasLayout packIncremental(const AtlasLayout& base, const std::vector<RdmId>& rdms,
                            const StoredFaces& stored,
                            RadianceFormat format = RadianceFormat::kFloat32);

}  // namespace rdm
