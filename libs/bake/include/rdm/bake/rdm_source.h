// Finished RDMs as the atlas and noise writers read them: one at a time, from memory or from
// a spill file, so that writing an atlas holds one page and one RDM, not the whole bake.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/base/status.h"

namespace rdm {

// What the writers need of an RDM without its texels: its faces' largest R, G or B (for the
// half format's tile exponents) and whether every texel is finite.
struct RdmDigest {
  RdmId id;
  std::array<bool, 6> skipped{};
  std::array<float, 6> face_max{};
  bool finite = true;
};
RdmDigest digestRdm(const RdmData& rdm);

class RdmSource {
 public:
  virtual ~RdmSource() = default;
  // One per RDM, in the order the RDMs were added; stable while the source lives.
  virtual std::vector<RdmId> ids() const = 0;
  // Reads every texel of a MemoryRdmSource (or a shard set); fails only on a read error.
  virtual Expected<std::vector<RdmDigest>> digests() const = 0;
  // Calls `use` with RDM i (its image and stderr_rgb); fails only on a read error.
  [[nodiscard]] virtual Status visit(size_t i,
                                     const std::function<void(const RdmData&)>& use) const = 0;
};

// A view of RDMs held in memory; keeps a reference to `rdms`.
class MemoryRdmSource final : public RdmSource {
 public:
  explicit MemoryRdmSource(const std::vector<RdmData>& rdms) : rdms_(rdms) {}
  std::vector<RdmId> ids() const override;
  Expected<std::vector<RdmDigest>> digests() const override;
  Status visit(size_t i, const std::function<void(const RdmData&)>& use) const override;

 private:
  const std::vector<RdmData>& rdms_;
};

// RDMs appended as they finish to an anonymous file in a directory (O_TMPFILE, or a
// temporary name unlinked at once), so nothing is left behind even after a SIGKILL. Holds
// sizeof(RdmDigest) + 24 bytes per RDM in memory; the file takes 28 bytes per texel
// (R, G, B, Z and the standard error of R, G, B, as float32). Each record's bytes carry an
// XXH3 64 kept in memory, checked by visit(): a record damaged on disk fails alone (kCorrupt,
// naming its slot and level), never reaching the job's results.
class RdmSpill final : public RdmSource {
 public:
  static Expected<std::unique_ptr<RdmSpill>> create(const std::string& dir);
  ~RdmSpill() override;
  RdmSpill(const RdmSpill&) = delete;
  RdmSpill& operator=(const RdmSpill&) = delete;

  // What one RDM takes in the file.
  static uint64_t fileBytes(const RdmId& id) {
    return uint64_t(2 * id.size) * uint64_t(3 * id.size) * 7 * sizeof(float);
  }
  // Thread-safe. A write error (a full disk) is kept: status() returns the first one.
  void append(const RdmData& rdm);
  Status status() const;
  size_t bytes() const { return end_.load(); }

  std::vector<RdmId> ids() const override;
  Expected<std::vector<RdmDigest>> digests() const override;
  Status visit(size_t i, const std::function<void(const RdmData&)>& use) const override;

 private:
  struct Record {
    RdmDigest digest;
    uint64_t offset = 0;
    uint64_t hash = 0;  // XXH3 64 of the image bytes, then the standard error's
    uint32_t max_samples = 0;
  };
  RdmSpill(int fd, std::string dir) : fd_(fd), dir_(std::move(dir)) {}

  const int fd_;
  const std::string dir_;
  std::atomic<uint64_t> end_{0};
  mutable std::mutex mutex_;  // records_ and error_
  std::vector<Record> records_;
  Status error_;
};

}  // namespace rdm
