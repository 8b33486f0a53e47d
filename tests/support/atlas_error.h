// The error of one atlas read back against another holding the same RDMs (the bc6h atlas
// against the float32 one): relative errors of R, G, B and of depth, tile by tile.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "rdm/atlas/atlas.h"

namespace rdm::test {

struct AtlasError {
  double mean = 0.0, p99 = 0.0;     // of |b - a| / a over R, G, B values with a > floor
  double max_depth_relative = 0.0;  // largest |b - a| / a over depths a > 0
  size_t values = 0;                // R, G, B values counted
};

// Every RDM of `a` must be in `b` (by slot and level).
inline AtlasError atlasError(const LoadedAtlas& a, const LoadedAtlas& b, float floor) {
  std::vector<double> errors;
  AtlasError out;
  for (const AtlasEntry& e : a.layout.entries) {
    const Image ta = rdmTexels(a, e), tb = rdmTexels(b, *b.layout.find(e.id.slot, e.id.level));
    for (size_t p = 0; p < ta.pixels.size() / 4; ++p) {
      for (size_t c = 0; c < 3; ++c) {
        const double va = ta.pixels[p * 4 + c], vb = tb.pixels[p * 4 + c];
        if (va > floor) errors.push_back(std::abs(vb - va) / va);
      }
      const double za = ta.pixels[p * 4 + 3], zb = tb.pixels[p * 4 + 3];
      if (za > 0.0)
        out.max_depth_relative = std::max(out.max_depth_relative, std::abs(zb - za) / za);
    }
  }
  std::sort(errors.begin(), errors.end());
  for (double v : errors) out.mean += v;
  out.values = errors.size();
  if (!errors.empty()) {
    out.mean /= double(errors.size());
    out.p99 = errors[errors.size() * 99 / 100];
  }
  return out;
}

}  // namespace rdm::test
