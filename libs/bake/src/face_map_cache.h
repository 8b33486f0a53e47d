// The radiance maps of one BakeSession's prefiltered faces (docs/spec.md section 3.1): traced by
// the first unit that needs one, shared by every level of that face, freed after its last
// consumer. A map depends only on (settings, slot, face), so which unit traces it changes
// nothing in the result.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/bake/face_map.h"

namespace rdm {

class FaceMapCache {
 public:
  using Key = std::pair<uint32_t, int>;  // (linear slot index, face)

  // Before any acquire: one more unit will consume the map of `key`.
  void expect(const Key& key) { entries_[key].consumers += 1; }
  bool expects(const Key& key) const { return entries_.count(key) != 0; }

  // The map of `key`, traced by `trace` if no unit traced it yet (others wait meanwhile).
  const FaceMap& acquire(const Key& key, const std::function<void(FaceMap&)>& trace) {
    Entry& e = entries_.at(key);
    std::call_once(e.once, [&] { trace(e.map); });
    return e.map;
  }
  // After a consumer used the map of `key`: the last one frees it.
  void release(const Key& key) {
    Entry& e = entries_.at(key);
    if (e.consumers.fetch_sub(1) != 1) return;
    e.map.map.reset();
    e.map.full_set = std::vector<uint32_t>(), e.map.first_set = std::vector<uint32_t>();
  }

 private:
  struct Entry {
    std::once_flag once;
    std::atomic<int> consumers{0};
    FaceMap map;
  };
  std::map<Key, Entry> entries_;
};

}  // namespace rdm
