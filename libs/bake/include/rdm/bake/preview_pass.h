// The preview pass of a progressive incremental job (docs/spec.md section 8.6): what it bakes
// and how its RDMs become rects of the job's atlas. One definition for the daemon and the
// core's IncrementalBaker.
#pragma once

#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/image/image.h"

namespace rdm {

// Sample settings of the passes: a preview at max(1, spp / kPreviewDivisor) samples per
// texel, at most kPreviewBounces bounces (direct light and the first reflection, what an edit
// changes most visibly), the naive estimator and half the hemisphere cap
// (max(2, max_hemisphere / 2)), then the job's own settings. The preview is naive because at
// 1 spp the prefiltered estimator's fixed costs (central rays at the finest level and the
// kernels) make it 2.6x dearer than naive on chess; half size because the large levels hold
// most texels (docs/performance.md, "Live rebakes"). One pass when the preview would not
// have at least 4x fewer samples per texel.
constexpr int kPreviewDivisor = 16;
constexpr int kPreviewBounces = 1;
std::vector<BakeSettings> progressivePasses(const BakeSettings& settings);

// The plan's RDMs at a pass's hemisphere sizes (the same slots and levels, in plan order).
std::vector<RdmId> atPassSizes(const std::vector<RdmId>& plan, const BakeSettings& pass);

// An RDM image (2s x 3s) as the image of the same RDM at size `size` >= s: texel (i, j) of
// each face takes texel (i s / size, j s / size) of that face, all four channels (nearest).
Image expandRdmImage(const Image& image, int size);

}  // namespace rdm
