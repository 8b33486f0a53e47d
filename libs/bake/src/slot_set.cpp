#include "rdm/bake/slot_set.h"

#include <algorithm>
#include <iterator>

#include "rdm/base/check.h"

namespace rdm {

void sortUniqueSlots(std::vector<uint32_t>& slots) {
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
}
namespace {

void putVarint(std::string& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(char(uint8_t(v) | 0x80));
    v >>= 7;
  }
  out.push_back(char(v));
}

bool getVarint(const std::string& in, size_t& at, uint64_t& v) {
  v = 0;
  for (int shift = 0; shift < 64 && at < in.size(); shift += 7) {
    const uint8_t byte = uint8_t(in[at++]);
    v |= uint64_t(byte & 0x7f) << shift;
    if (!(byte & 0x80)) return true;
  }
  return false;
}

// Calls run(first, last) for each run [first, last]; false on malformed bytes.
template <class Run>
bool forEachRun(const std::string& bytes, Run&& run) {
  size_t at = 0;
  uint64_t next = 0;  // the smallest index the next run may start at
  while (at < bytes.size()) {
    uint64_t gap = 0, extra = 0;
    if (!getVarint(bytes, at, gap) || !getVarint(bytes, at, extra)) return false;
    const uint64_t first = next + gap, last = first + extra;
    if (gap > UINT32_MAX || extra > UINT32_MAX || last > UINT32_MAX) return false;
    if (!run(uint32_t(first), uint32_t(last))) return true;
    next = last + 2;  // runs are maximal: one index apart at least
  }
  return true;
}

class RunWriter {
 public:
  // Runs come in rising order; touching or overlapping ones join.
  void add(uint32_t first, uint32_t last) {
    if (open_ && uint64_t(first) <= uint64_t(last_) + 1) {
      last_ = std::max(last_, last);
      return;
    }
    flush();
    first_ = first, last_ = last, open_ = true;
  }
  void finish(std::string& bytes, uint64_t& count) {
    flush();
    bytes.swap(out_), count = count_;
  }

 private:
  void flush() {
    if (!open_) return;
    putVarint(out_, uint64_t(first_) - next_);
    putVarint(out_, uint64_t(last_ - first_));
    count_ += uint64_t(last_ - first_) + 1;
    next_ = uint64_t(last_) + 2;
  }
  std::string out_;
  uint64_t count_ = 0, next_ = 0;
  uint32_t first_ = 0, last_ = 0;
  bool open_ = false;
};

}  // namespace

SlotSet SlotSet::fromSorted(const std::vector<uint32_t>& sorted) {
  RDM_CHECK(std::adjacent_find(sorted.begin(), sorted.end(), std::greater_equal<uint32_t>()) ==
            sorted.end());
  SlotSet s;
  RunWriter w;
  for (uint32_t v : sorted) w.add(v, v);
  w.finish(s.bytes_, s.count_);
  return s;
}

std::optional<SlotSet> SlotSet::fromBytes(std::string bytes, uint64_t max_count) {
  SlotSet s;
  bool within = true;
  const bool well_formed = forEachRun(bytes, [&](uint32_t first, uint32_t last) {
    s.count_ += uint64_t(last - first) + 1;
    return within = s.count_ <= max_count;
  });
  if (!well_formed || !within) return std::nullopt;
  s.bytes_ = std::move(bytes);
  return s;
}

std::vector<uint32_t> SlotSet::values() const {
  std::vector<uint32_t> out;
  out.reserve(size_t(count_));
  forEachRun(bytes_, [&](uint32_t first, uint32_t last) {
    for (uint64_t v = first; v <= last; ++v) out.push_back(uint32_t(v));
    return true;
  });
  return out;
}

void SlotSet::unite(const std::vector<uint32_t>& other) {
  if (other.empty()) return;
  if (empty()) {
    *this = fromSorted(other);
    return;
  }
  RunWriter w;
  auto o = other.begin();
  forEachRun(bytes_, [&](uint32_t first, uint32_t last) {
    for (; o != other.end() && *o < first; ++o) w.add(*o, *o);
    w.add(first, last);
    while (o != other.end() && *o <= last) ++o;
    return true;
  });
  for (; o != other.end(); ++o) w.add(*o, *o);
  w.finish(bytes_, count_);
}

bool SlotSet::meets(const std::vector<uint32_t>& sorted) const {
  bool met = false;
  auto o = sorted.begin();
  forEachRun(bytes_, [&](uint32_t first, uint32_t last) {
    o = std::lower_bound(o, sorted.end(), first);
    if (o == sorted.end()) return false;
    met = *o <= last;
    return !met;
  });
  return met;
}

}  // namespace rdm
