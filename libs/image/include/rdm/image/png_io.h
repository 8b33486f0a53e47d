// PNG output (8-bit RGB or RGBA) for visualisations, encoded by stb_image_write.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rdm/base/status.h"

namespace rdm {

// Writes `pixels` (row-major, top row first, `channels` interleaved bytes per pixel; 3 = RGB,
// 4 = RGBA) as a PNG through writeFileAtomic, so `path` is never left half-written. A channel count
// other than 3 or 4, a non-positive size or a pixel count that does not match are programmer bugs
// (RDM_CHECK); IO failures return an error naming the file.
Status writePng(const std::string& path, int width, int height, int channels,
                const std::vector<uint8_t>& pixels);

}  // namespace rdm
