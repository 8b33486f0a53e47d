// The per-RDM store of a job (docs/spec.md, "Per-RDM store"): the texels of every RDM the
// job itself baked, written once when the job ends, so that deltas and single-RDM
// downloads read exactly the rects they need instead of decoding atlas pages.
//
// Layout (little-endian): magic "RDMSTOR2", u32 count, then count entries of
// {i32 i, j, k, level, size; u64 byte offset; u64 XXH3 64 of the texel bytes}, then the
// texels of each RDM (2S x 3S RGBZ float32, row-major) at its offset. A read verifies the
// checksum, so a damaged RDM is refused, never served or copied into a later job. Stores of
// the first format ("RDMSTOR1", entries without the checksum) still read, unverified.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/base/status.h"

namespace rdm {

constexpr const char* kRdmStoreFile = "rdms.store";  // in a job's out/ directory

// Writes `rdms` atomically (temp, fsync, rename) to `path`, one RDM at a time.
Status writeRdmStore(const std::string& path, const RdmSource& rdms);

class RdmStoreReader {
 public:
  // Reads the table of contents only.
  static Expected<RdmStoreReader> open(const std::string& path);
  bool contains(const RdmKey& key) const { return toc_.count(key) != 0; }
  // One RDM's image, read straight from its offset.
  Expected<Image> read(const RdmKey& key) const;

 private:
  struct Slot {
    int size = 0;
    uint64_t offset = 0;
    uint64_t hash = 0;     // XXH3 64 of the texels' bytes
    bool checked = false;  // false for a store of the first format, which has none
  };
  std::string path_;
  uint64_t file_size_ = 0;
  std::map<RdmKey, Slot> toc_;
};

}  // namespace rdm
