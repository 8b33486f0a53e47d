#if RDM_HAVE_VULKAN

#include "vulkan_bake_plan.h"

#include <algorithm>
#include <array>
#include <map>

#include "rdm/bake/bake_stats.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm::vkbake {
namespace {

using glm::ivec3;

}  // namespace

// The slots an RDM's central rays enter, gathered ray by ray: a bitset over the grid answers
// membership, the member list gives the sorted set and clears the bitset for the next RDM.
class RdmTexels::CentralSlots {
 public:
  explicit CentralSlots(size_t slots) : bits_((slots + 63) / 64, 0) {}
  std::vector<uint32_t> ray;  // exactCentralDepth appends one ray's slots here
  void addRay() {
    for (uint32_t s : ray) {
      uint64_t& word = bits_[s >> 6];
      const uint64_t bit = uint64_t(1) << (s & 63);
      if (!(word & bit)) word |= bit, members_.push_back(s);
    }
    ray.clear();
  }
  std::vector<uint32_t> take() {
    for (uint32_t s : members_) bits_[s >> 6] = 0;
    std::sort(members_.begin(), members_.end());
    std::vector<uint32_t> out;
    out.swap(members_);
    return out;
  }

 private:
  std::vector<uint64_t> bits_;
  std::vector<uint32_t> members_;
};

namespace {

gpu::GpuJob texelJob(const ivec3& slot, int level, int face, int size, int i, int j) {
  gpu::GpuJob g;
  g.data = glm::uvec4(slotKey(slot), uint32_t(level) | uint32_t(face) << 4 | uint32_t(size) << 8,
                      uint32_t(i) | uint32_t(j) << 16, 0u);
  return g;
}

class Planner {
 public:
  Planner(const VoxelWorld& world, const BakeSettings& settings, BakeResult& result)
      : world_(world), settings_(settings), result_(result) {}

  BakePlan take() { return std::move(plan_); }

  void addRdm(const RdmId& id) {
    RdmData data;
    data.id = id;
    data.max_samples = uint32_t(settings_.spp);
    const int r = int(result_.rdms.size());
    const int map_level = radianceMapLevel(world_, settings_, id.slot);
    const int maps_owner = map_level >= 0 ? slotMaps(id.slot, map_level) : -1;
    const int owner = maps_owner >= 0 ? -1 : int(plan_.owners.size());
    if (owner >= 0) plan_.owners.push_back({r, {}, {}, false});
    plan_.maps_owner.push_back(maps_owner);
    plan_.pending.push_back(0);
    for (int f = 0; f < 6; ++f) {
      data.skipped[size_t(f)] = faceSkipped(world_, id.slot, f);
      if (data.skipped[size_t(f)]) {
        ++result_.report.faces_skipped;
        continue;
      }
      ++result_.report.faces_baked;
      if (maps_owner >= 0) {
        plan_.maps[size_t(slot_maps_.at(world_.slotLinear(id.slot))[size_t(f)])]
            .consumers.push_back(r);
        ++plan_.pending[size_t(r)];
      } else {
        addRdmFaceJobs(id, r, owner, f);
      }
    }
    result_.rdms.push_back(std::move(data));
  }

 private:
  void addRdmFaceJobs(const RdmId& id, int r, int owner, int f) {
    const int S = id.size;
    const int group_start = int(plan_.jobs.size());
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i) {
        const int group = id.level == shared::kDiffuseLevel ? group_start : int(plan_.jobs.size());
        plan_.jobs.push_back(
            {r, -1, owner, f, i, j, group, texelJob(id.slot, id.level, f, S, i, j)});
        ++plan_.pending[size_t(r)];
      }
  }

  // The owner of the maps of `slot`, planning them (every face that is baked) at first use.
  int slotMaps(const ivec3& slot, int map_level) {
    const auto linear = world_.slotLinear(slot);
    if (auto it = slot_maps_owner_.find(linear); it != slot_maps_owner_.end()) return it->second;
    const int owner = int(plan_.owners.size());
    plan_.owners.push_back({-1, {}, {}, false});
    slot_maps_owner_[linear] = owner;
    std::array<int, 6>& maps = slot_maps_[linear];
    maps.fill(-1);
    const int S = shared::hemisphereSize(map_level, settings_.max_hemisphere);
    for (int f = 0; f < 6; ++f) {
      if (faceSkipped(world_, slot, f)) continue;
      const int m = int(plan_.maps.size());
      maps[size_t(f)] = m;
      PlannedMap& map = plan_.maps.emplace_back();
      map.slot = slot, map.face = f, map.size = S;
      map.builder = std::make_unique<FaceMapBuilder>(S);
      map.jobs_left = S * S;
      for (int j = 0; j < S; ++j)
        for (int i = 0; i < S; ++i) {
          gpu::GpuJob g = texelJob(slot, 0, f, S, i, j);
          g.data.y |= gpu::kJobFootprintSobol;
          plan_.jobs.push_back({-1, m, owner, f, i, j, int(plan_.jobs.size()), g});
        }
    }
    return owner;
  }

  const VoxelWorld& world_;
  const BakeSettings& settings_;
  BakeResult& result_;
  BakePlan plan_;
  std::map<int, int> slot_maps_owner_;           // linear slot -> owner of its maps
  std::map<int, std::array<int, 6>> slot_maps_;  // linear slot -> map per face, -1 skipped
};

}  // namespace

BakePlan planBake(const VoxelWorld& world, const BakeSettings& settings,
                  const std::vector<RdmId>& rdms, BakeResult& result) {
  Planner planner(world, settings, result);
  for (const RdmId& id : rdms) planner.addRdm(id);
  return planner.take();
}

RdmTexels::RdmTexels(const VoxelWorld& world, bool record, size_t rdms)
    : world_(world),
      record_(record),
      central_(std::make_unique<CentralSlots>(record ? world.slots.size() : 0)),
      allocated_(rdms, 0) {}

RdmTexels::~RdmTexels() = default;

void RdmTexels::ensure(RdmData& rdm, size_t r) {
  if (allocated_[r]) return;
  allocated_[r] = 1;
  peak_ = std::max(peak_, ++held_);
  rdm.image = Image(2 * rdm.id.size, 3 * rdm.id.size, 4);
  rdm.stderr_rgb.assign(size_t(rdm.image.width) * rdm.image.height * 3, 0.0f);
  const int S = rdm.id.size;
  for (int f = 0; f < 6; ++f) {
    if (rdm.skipped[size_t(f)]) continue;
    const ivec3 origin = rdm.id.slot * 16 + ivec3(8) + 8 * shared::faceNormal(f);
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i) {
        const ivec3 d = shared::texelCentralDirection(i, j, S);
        const ivec3 dir = d.x * shared::faceTangent(f) + d.y * shared::faceBitangent(f) +
                          d.z * shared::faceNormal(f);
        const glm::ivec2 px = shared::rdmTexelPixel(0, 0, S, f, i, j);
        rdm.image.at(px.x, px.y, 3) =
            exactCentralDepth(world_, origin, dir, record_ ? &central_->ray : nullptr);
        if (record_) central_->addRay();
      }
  }
  if (record_) {
    std::vector<uint32_t> central = central_->take();
    rdm.first_set.insert(rdm.first_set.end(), central.begin(), central.end());
    rdm.full_set.insert(rdm.full_set.end(), central.begin(), central.end());
  }
}

void RdmTexels::release(RdmData& rdm) {
  rdm.image = Image();
  rdm.stderr_rgb = std::vector<float>();
  rdm.full_set = std::vector<uint32_t>(), rdm.first_set = std::vector<uint32_t>();
  --held_;
}

void deriveFace(const FaceMap& map, int face, RdmData& rdm) {
  const int S = rdm.id.size;
  const FaceMapDerivation derive(map, rdm.id.level, S);
  for (int j = 0; j < S; ++j)
    for (int i = 0; i < S; ++i) {
      glm::vec3 mean, variance;
      derive.texel(i, j, mean, variance);
      storeRadiance(rdm, face, i, j, glm::dvec3(mean), glm::sqrt(glm::dvec3(variance)));
    }
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
