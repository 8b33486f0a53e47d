// denoiseRdms: the denoiser over a source of any size, a batch of RDMs at a time, each read
// with its plane neighbours (from the source or its context) and filtered on the CPU's
// workers or on a DenoiseDevice, then appended in the source's order.
#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>

#include "rdm/bake/denoise.h"
#include "rdm/base/parallel.h"

namespace rdm {

namespace {

// Where each RDM is: in `rdms` (first) or in `context`.
struct Locator {
  std::map<SlotLevelKey, std::pair<const RdmSource*, size_t>> where;
  Locator(const RdmSource& rdms, const RdmSource* context) {
    if (context) add(*context);
    add(rdms);  // overrides the context's
  }
  void add(const RdmSource& source) {
    const std::vector<RdmId> ids = source.ids();
    for (size_t i = 0; i < ids.size(); ++i)
      where[slotLevelKey(ids[i].slot, ids[i].level)] = {&source, i};
  }
};

Status readRdm(const std::pair<const RdmSource*, size_t>& at, RdmData& out) {
  return at.first->visit(at.second, [&](const RdmData& d) { out = d; });
}

// One RDM of a batch with the neighbours it was read with.
struct Loaded {
  RdmData center;
  std::map<SlotLevelKey, RdmData> near;
  DenoiseInput input;
};

// RDM i of `rdms` and its six face neighbours, read through `locator`.
Status load(const RdmSource& rdms, size_t i, const Locator& locator, Loaded& out) {
  out = {};
  if (Status st = readRdm({&rdms, i}, out.center); !st) return st;
  out.input.center = &out.center;
  for (int axis = 0; axis < 3; ++axis) {
    const std::array<glm::ivec3, 4> slots = planeNeighbourSlots(out.center.id.slot, axis);
    for (size_t n = 0; n < 4; ++n) {
      const SlotLevelKey key = slotLevelKey(slots[n], out.center.id.level);
      auto found = locator.where.find(key);
      if (found == locator.where.end()) continue;
      auto [it, fresh] = out.near.try_emplace(key);
      if (fresh) {
        if (Status st = readRdm(found->second, it->second); !st) return st;
      }
      out.input.neighbours[size_t(axis)][n] = &it->second;
    }
  }
  return {};
}

}  // namespace

Status denoiseRdms(const RdmSource& rdms, const RdmSource* context, RdmSpill& out,
                   const DenoiseSettings& settings, int threads, DenoiseStats& stats,
                   DenoiseDevice* device) {
  const auto start = std::chrono::steady_clock::now();
  const Locator locator(rdms, context);
  const size_t count = rdms.ids().size();
  const size_t batch =
      device ? std::max<size_t>(1, device->batchRdms()) : size_t(2 * workerCount(threads));
  std::vector<Loaded> loaded(batch);
  std::vector<RdmData> done(batch);
  std::vector<DenoiseStats> part(batch);
  std::vector<Status> failed(batch);
  std::vector<uint64_t> cpu(batch, 0);
  for (size_t first = 0; first < count; first += batch) {
    const size_t n = std::min(batch, count - first);
    // Workers read (and on the CPU filter) one RDM each; a device then takes the batch.
    parallelFor(n, {threads}, [&](size_t k) {
      const uint64_t cpu0 = threadCpuNanoseconds();
      part[k] = {};
      failed[k] = load(rdms, first + k, locator, loaded[k]);
      if (failed[k] && !device)
        done[k] = denoiseRdm(loaded[k].center, loaded[k].input.neighbours, settings, part[k]);
      cpu[k] += threadCpuNanoseconds() - cpu0;
      return bool(failed[k]);
    });
    for (size_t k = 0; k < n; ++k) {
      if (!failed[k]) return failed[k];
    }
    if (device) {
      std::vector<DenoiseInput> inputs;
      for (size_t k = 0; k < n; ++k) inputs.push_back(loaded[k].input);
      done.resize(n);
      if (Status s = device->denoise(inputs, settings, done, part[0]); !s) return s;
    }
    for (size_t k = 0; k < n; ++k) {
      out.append(done[k]);
      stats.add(part[k]);
    }
  }
  if (Status s = out.status(); !s) return s;
  for (uint64_t c : cpu) stats.cpu_seconds += double(c) * 1e-9;
  stats.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {};
}

}  // namespace rdm
