// The bake's noise map: per-texel relative standard error (luminance of the standard error
// over luminance of the value; 0 for skipped faces, uncovered texels and black texels), laid
// out like the atlas pages, one float channel "E" per page: noise.exr, noise.page<N>.exr
// (docs/spec.md section 4). `rdm bake` and a daemon's full jobs write it.
#pragma once

#include <string>
#include <vector>

#include "rdm/atlas/atlas.h"
#include "rdm/base/status.h"

namespace rdm {

inline constexpr const char* kNoiseChannel = "E";

std::string noisePageFileName(int page);

// One page at a time: holds one page and one RDM besides `source`. Refuses (kInvalidInput)
// an RDM of `source` without its standard error (one copied from a daemon job's store).
// Tiles lie where index.json puts them: in `layout`.
Status writeNoiseMaps(const std::string& dir, const AtlasLayout& layout, const RdmSource& source);

}  // namespace rdm
