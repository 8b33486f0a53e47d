// A set of slot indices (VoxelWorld::slotLinear) held as runs of consecutive indices, so
// that a job keeps every RDM's slot sets in memory at a cost that follows the set's shape,
// not its size: a path set that covers a region of the grid is a few runs per row.
//
// Encoding (also the bytes rdms.bin stores, docs/spec.md section 8.10): per run, in rising
// order, two unsigned LEB128 varints: the gap from the end of the previous run (from 0 for
// the first) and the run's length minus one.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rdm {

// Sorts `slots` and drops repeats: a slot list as recorded (any order, repeats) made a set.
void sortUniqueSlots(std::vector<uint32_t>& slots);

class SlotSet {
 public:
  SlotSet() = default;
  // `sorted` must be strictly increasing (RDM_CHECK).
  static SlotSet fromSorted(const std::vector<uint32_t>& sorted);
  // Validates bytes read from a file: nullopt when cut short, overflowing 32 bits or when
  // the runs would exceed `max_count` indices.
  static std::optional<SlotSet> fromBytes(std::string bytes, uint64_t max_count);

  const std::string& bytes() const { return bytes_; }
  uint64_t count() const { return count_; }
  bool empty() const { return count_ == 0; }
  std::vector<uint32_t> values() const;
  // this = this U other; `other` strictly increasing.
  void unite(const std::vector<uint32_t>& other);
  // Whether any index of `sorted` (increasing) is in the set.
  bool meets(const std::vector<uint32_t>& sorted) const;

  bool operator==(const SlotSet& o) const { return bytes_ == o.bytes_; }

 private:
  std::string bytes_;
  uint64_t count_ = 0;
};

}  // namespace rdm
