#if RDM_HAVE_VULKAN

#include "vulkan_prefilter.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm::vkbake {
namespace {

bool roughLevel(int level) {
  return level > 0 && level < shared::kDiffuseLevel;
}

}  // namespace

Status DevicePrefilter::ensure(Buffer*& buffer, uint64_t bytes, const char* what) {
  if (buffer && buffer->size >= bytes) return {};
  // Grown buffers stay in the bake's Buffers until it ends; growth doubles, so they add up to
  // at most twice the largest.
  auto made = buffers_.create(std::max<uint64_t>(bytes, buffer ? 2 * buffer->size : 0), what);
  if (!made) return made.status();
  buffer = *made;
  return {};
}

Status DevicePrefilter::prepare(const BakePlan& plan, const std::vector<RdmData>& rdms) {
  std::vector<uint32_t> begin;
  std::vector<gpu::GpuKernelTap> taps;
  for (const PlannedMap& map : plan.maps) {
    for (int r : map.consumers) {
      const RdmId& id = rdms[size_t(r)].id;
      if (!roughLevel(id.level)) continue;
      const auto key = std::make_tuple(id.level, id.size, map.size);
      if (kernel_begin_.count(key)) continue;
      const PrefilterKernel& kernel = prefilterKernel(id.level, id.size, map.size);
      kernel_begin_[key] = uint32_t(begin.size());
      const uint32_t base = uint32_t(taps.size());
      for (uint32_t b : kernel.begin) begin.push_back(base + b);
      for (const KernelTap& t : kernel.taps) {
        uint32_t weight_bits;
        std::memcpy(&weight_bits, &t.weight, sizeof(weight_bits));
        taps.push_back({glm::uvec4(t.texel, weight_bits, 0u, 0u)});
      }
    }
  }
  if (kernel_begin_.empty()) return {};
  if (Status s = ensure(begin_, begin.size() * sizeof(uint32_t), "prefilter kernel"); !s) return s;
  if (Status s = ensure(taps_, taps.size() * sizeof(gpu::GpuKernelTap), "prefilter tap"); !s)
    return s;
  std::memcpy(begin_->mapped, begin.data(), begin.size() * sizeof(uint32_t));
  std::memcpy(taps_->mapped, taps.data(), taps.size() * sizeof(gpu::GpuKernelTap));
  return {};
}

Status DevicePrefilter::derive(FaceMap map, int face, const std::vector<int>& consumers,
                               std::vector<RdmData>& rdms) {
  bool queued = false;
  for (int r : consumers) {
    RdmData& rdm = rdms[size_t(r)];
    if (!roughLevel(rdm.id.level)) {
      deriveFace(map, face, rdm);
      face_done_(r);
      continue;
    }
    const auto key = std::make_tuple(rdm.id.level, rdm.id.size, map.map->size());
    queue_.push_back({int(maps_.size()), r, face, kernel_begin_.at(key)});
    queued_texels_ += uint64_t(rdm.id.size) * uint64_t(rdm.id.size);
    queued = true;
  }
  if (queued) maps_.push_back(std::move(map));
  return queued_texels_ >= max_queued_ ? flush(rdms) : Status{};
}

Status DevicePrefilter::flush(std::vector<RdmData>& rdms) {
  if (queue_.empty()) return {};
  const auto start = std::chrono::steady_clock::now();
  std::vector<uint32_t> map_base(maps_.size());
  uint64_t map_texels = 0;
  for (size_t m = 0; m < maps_.size(); ++m)
    map_base[m] = uint32_t(map_texels), map_texels += maps_[m].map->means().size();
  if (Status s = ensure(map_texels_, map_texels * sizeof(gpu::GpuMapTexel), "radiance map"); !s)
    return s;
  if (Status s = ensure(derived_, queued_texels_ * sizeof(gpu::GpuMapTexel), "derived texel"); !s)
    return s;
  if (Status s = ensure(tasks_, queue_.size() * sizeof(gpu::GpuDeriveTask), "derive task"); !s)
    return s;
  auto* texels = static_cast<gpu::GpuMapTexel*>(map_texels_->mapped);
  for (size_t m = 0; m < maps_.size(); ++m) {
    const auto& means = maps_[m].map->means();
    const auto& variances = maps_[m].map->variances();
    for (size_t t = 0; t < means.size(); ++t)
      texels[map_base[m] + t] = {glm::vec4(means[t], 0.0f), glm::vec4(variances[t], 0.0f)};
  }
  auto* tasks = static_cast<gpu::GpuDeriveTask*>(tasks_->mapped);
  uint32_t out = 0;
  std::vector<uint32_t> out_base(queue_.size());
  for (size_t k = 0; k < queue_.size(); ++k) {
    const Task& t = queue_[k];
    const uint32_t count = uint32_t(rdms[size_t(t.rdm)].id.size * rdms[size_t(t.rdm)].id.size);
    tasks[k].data = glm::uvec4(map_base[size_t(t.map)], t.begin, out, count);
    out_base[k] = out, out += count;
  }
  auto pipeline = ctx_.prefilterPipeline();
  if (!pipeline) return pipeline.status();
  ctx_.bind({map_texels_, begin_, taps_, tasks_, derived_}, ctx_.prefilter_set);
  RDM_CHECK(out / gpu::kWorkgroupSize < ctx_.props.limits.maxComputeWorkGroupCount[0]);
  const gpu::GpuPush push{glm::uvec4(uint32_t(queue_.size()), out, 0u, 0u)};
  if (Status s = ctx_.dispatch(*pipeline, push, out, nullptr, ctx_.prefilter_set); !s) return s;
  ++dispatches_;
  const auto* derived = static_cast<const gpu::GpuMapTexel*>(derived_->mapped);
  for (size_t k = 0; k < queue_.size(); ++k) {
    RdmData& rdm = rdms[size_t(queue_[k].rdm)];
    const int S = rdm.id.size;
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i) {
        const gpu::GpuMapTexel& d = derived[out_base[k] + uint32_t(j * S + i)];
        storeRadiance(rdm, queue_[k].face, i, j, glm::dvec3(glm::vec3(d.mean)),
                      glm::sqrt(glm::dvec3(glm::vec3(d.variance))));
      }
  }
  for (const Task& t : queue_) face_done_(t.rdm);
  texels_derived_ += queued_texels_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  queue_.clear(), maps_.clear(), queued_texels_ = 0;
  return {};
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
