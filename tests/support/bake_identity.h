// Bit identity of two bakes, for the determinism tests (threads, shards, resume, backends):
// the same RDMs in the same order with byte-equal radiance, depth and standard errors, the
// same skipped faces and the same sample counts.
#pragma once

#include <cstring>
#include <vector>

#include "rdm/bake/bake.h"

namespace rdm::test {

inline bool sameBytes(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

inline bool bitIdentical(const BakeResult& a, const BakeResult& b) {
  if (a.rdms.size() != b.rdms.size()) return false;
  for (size_t i = 0; i < a.rdms.size(); ++i) {
    const RdmData& x = a.rdms[i];
    const RdmData& y = b.rdms[i];
    if (!(x.id == y.id) || !sameBytes(x.image.pixels, y.image.pixels) ||
        !sameBytes(x.stderr_rgb, y.stderr_rgb) || x.skipped != y.skipped ||
        x.max_samples != y.max_samples)
      return false;
  }
  return true;
}

}  // namespace rdm::test
