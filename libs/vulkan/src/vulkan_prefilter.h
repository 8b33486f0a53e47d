// The prefilter pass of a Vulkan bake (shaders/prefilter.comp, docs/vulkan.md): rough levels
// of the prefiltered estimator derived on the device from finished radiance maps, with the
// CPU's kernels (rdm/bake/prefilter.h) uploaded once per bake. Level 0 (the map itself) and
// level 7 (the map's diffuse mean) are copies, written on the host by deriveFace.
#pragma once

#if RDM_HAVE_VULKAN

#include <algorithm>
#include <functional>
#include <map>
#include <tuple>
#include <vector>

#include "rdm/bake/face_map.h"
#include "vulkan_bake_plan.h"
#include "vulkan_context.h"

namespace rdm::vkbake {

class DevicePrefilter {
 public:
  // `max_queued`: derived texels queued before a flush; `face_done(r)`: one face of RDM r
  // is written.
  DevicePrefilter(Context& ctx, Buffers& buffers, uint64_t max_queued,
                  std::function<void(int)> face_done)
      : ctx_(ctx),
        buffers_(buffers),
        max_queued_(std::max<uint64_t>(1, max_queued)),
        face_done_(std::move(face_done)) {}

  // Uploads the kernels of every rough level the plan derives from a map.
  Status prepare(const BakePlan& plan, const std::vector<RdmData>& rdms);
  // Face `face` of each consumer from finished `map`: rough levels queued for the device
  // (flushed when the queue is large), the others written now.
  Status derive(FaceMap map, int face, const std::vector<int>& consumers,
                std::vector<RdmData>& rdms);
  // Runs the queued rough levels and writes their texels and standard errors.
  Status flush(std::vector<RdmData>& rdms);
  uint64_t texelsDerived() const { return texels_derived_; }
  uint64_t dispatches() const { return dispatches_; }
  double seconds() const { return seconds_; }

 private:
  struct Task {
    int map;  // index into maps_
    int rdm, face;
    uint32_t begin;  // the kernel's first begin[] entry
  };
  Status ensure(Buffer*& buffer, uint64_t bytes, const char* what);

  Context& ctx_;
  Buffers& buffers_;
  const uint64_t max_queued_;
  const std::function<void(int)> face_done_;
  std::map<std::tuple<int, int, int>, uint32_t> kernel_begin_;  // (level, S, map S) -> begin
  Buffer *begin_ = nullptr, *taps_ = nullptr, *tasks_ = nullptr;
  Buffer *map_texels_ = nullptr, *derived_ = nullptr;
  std::vector<FaceMap> maps_;  // finished maps of the queued tasks
  std::vector<Task> queue_;
  uint64_t queued_texels_ = 0, texels_derived_ = 0, dispatches_ = 0;
  double seconds_ = 0.0;
};

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
