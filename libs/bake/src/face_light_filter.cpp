#include "rdm/bake/face_light_filter.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "rdm/base/check.h"
#include "rdm/base/parallel.h"
#include "rdm/scene/lights.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

constexpr size_t kNoFace = ~size_t(0);

// Solid voxels among the 3 x 3 x 2 cells in front of face `face` of world voxel `voxel`:
// the geometry that shades it from nearby.
uint8_t frontOccupancy(const VoxelWorld& world, const glm::ivec3& voxel, int face) {
  const glm::ivec3 n = shared::faceNormal(face), t = shared::faceTangent(face),
                   b = shared::faceBitangent(face);
  uint8_t count = 0;
  for (int k = 1; k <= 2; ++k)
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i) count += world.voxelAt(voxel + k * n + i * t + j * b) != 0;
  return count;
}

glm::ivec3 faceVoxel(const glm::ivec3& slot, uint32_t texel) {
  const int v = int(texel / shared::kFaceCount);
  return slot * 16 + glm::ivec3(v % 16, (v / 16) % 16, v / 256);
}

// Every current face of a light, flat: its value, luminance and front occupancy, found by
// world voxel and direction.
class FlatFaces {
 public:
  FlatFaces(const VoxelWorld& world, const FaceLight& light, int threads)
      : world_(world),
        light_(light),
        row_of_slot_(size_t(world.size.x) * world.size.y * world.size.z, -1) {
    current_.resize(light.slots.size(), 0);
    ParallelOptions parallel;
    parallel.threads = threads;
    parallelFor(light.slots.size(), parallel, [&](size_t r) {
      const FaceLightSlot& s = light.slots[r];
      current_[r] = world.slotInGrid(s.slot) && s.faces == exposedFaces(world, s.slot);
      return true;
    });
    first_.resize(light.slots.size(), 0);
    size_t count = 0;
    for (size_t r = 0; r < light.slots.size(); ++r) {
      if (!current_[r]) continue;
      row_of_slot_[size_t(world.slotLinear(light.slots[r].slot))] = int32_t(r);
      first_[r] = count;
      count += light.slots[r].faces.size();
    }
    value_.resize(count);
    luminance_.resize(count);
    occupancy_.resize(count);
    parallelFor(light.slots.size(), parallel, [&](size_t r) {
      if (!current_[r]) return true;
      const FaceLightSlot& s = light.slots[r];
      for (size_t i = 0; i < s.faces.size(); ++i) {
        value_[first_[r] + i] = s.light[i];
        luminance_[first_[r] + i] = rdm::luminance(s.light[i]);
        occupancy_[first_[r] + i] = frontOccupancy(world, faceVoxel(s.slot, s.faces[i]),
                                                   int(s.faces[i] % shared::kFaceCount));
      }
      return true;
    });
  }

  bool current(size_t row) const { return current_[row] != 0; }
  size_t first(size_t row) const { return first_[row]; }
  float luminance(size_t flat) const { return luminance_[flat]; }
  const glm::vec3& value(size_t flat) const { return value_[flat]; }
  uint8_t occupancy(size_t flat) const { return occupancy_[flat]; }

  // The flat index of face `face` of world voxel `voxel`, or kNoFace.
  size_t find(const glm::ivec3& voxel, int face) const {
    const glm::ivec3 slot = voxel >> 4;  // floor division by the block size
    if (!world_.slotInGrid(slot)) return kNoFace;
    const int32_t row = row_of_slot_[size_t(world_.slotLinear(slot))];
    if (row < 0) return kNoFace;
    const FaceLightSlot& s = light_.slots[size_t(row)];
    const glm::ivec3 l = voxel - slot * 16;
    const uint32_t texel = shared::faceLightTexel(l.x + 16 * l.y + 256 * l.z, face);
    const auto it = std::lower_bound(s.faces.begin(), s.faces.end(), texel);
    if (it == s.faces.end() || *it != texel) return kNoFace;
    return first_[size_t(row)] + size_t(it - s.faces.begin());
  }

 private:
  const VoxelWorld& world_;
  const FaceLight& light_;
  std::vector<int32_t> row_of_slot_;
  std::vector<uint8_t> current_;
  std::vector<size_t> first_;
  std::vector<glm::vec3> value_;
  std::vector<float> luminance_;
  std::vector<uint8_t> occupancy_;
};

float gaussian(float d, float width) {
  return std::exp(-0.5f * (d * d) / (width * width));
}

// The spatial and occupancy weights, which take few values, tabulated once.
class StaticWeights {
 public:
  explicit StaticWeights(const FaceLightFilter& filter) : side_(2 * filter.radius + 1) {
    spatial_.resize(size_t(side_ * side_));
    for (int j = 0; j < side_; ++j)
      for (int i = 0; i < side_; ++i) {
        const int x = i - filter.radius, y = j - filter.radius;
        spatial_[size_t(j * side_ + i)] = gaussian(std::sqrt(float(x * x + y * y)), filter.sigma);
      }
    for (int d = 0; d <= kMaxOccupancy; ++d)
      occupancy_[size_t(d)] = filter.occupancy > 0.0f ? gaussian(float(d), filter.occupancy) : 1.0f;
  }
  float at(int i, int j, int occupancy_difference) const {
    return spatial_[size_t(j * side_ + i)] * occupancy_[size_t(std::abs(occupancy_difference))];
  }

 private:
  static constexpr int kMaxOccupancy = 18;
  int side_;
  std::vector<float> spatial_;
  std::array<float, kMaxOccupancy + 1> occupancy_{};
};

// One slot's faces by slot-space texel (shared::faceLightTexel), for the lookups that stay
// in the slot: most of them. A worker's table, set for one slot at a time.
class SlotTable {
 public:
  SlotTable() : index_(size_t(shared::kBlockVoxelCount) * shared::kFaceCount, kNoFace) {}
  void set(const FaceLightSlot& slot, size_t first) {
    for (size_t i = 0; i < slot.faces.size(); ++i) index_[slot.faces[i]] = first + i;
  }
  void clear(const FaceLightSlot& slot) {
    for (uint32_t f : slot.faces) index_[f] = kNoFace;
  }
  size_t at(uint32_t texel) const { return index_[texel]; }

 private:
  std::vector<size_t> index_;
};

struct FilterContext {
  const FlatFaces& faces;
  const FaceLightFilter& filter;
  const StaticWeights& weights;
  float relative_noise;
};

glm::vec3 filteredFace(const FilterContext& c, const SlotTable& table, const glm::ivec3& slot,
                       const glm::ivec3& voxel, int face, size_t centre) {
  const glm::ivec3 t = shared::faceTangent(face), b = shared::faceBitangent(face);
  const int radius = c.filter.radius;
  const float centre_luminance = c.faces.luminance(centre);
  const int centre_occupancy = c.faces.occupancy(centre);
  glm::dvec3 sum(0.0);
  double weight_sum = 0.0;
  for (int j = -radius; j <= radius; ++j) {
    for (int i = -radius; i <= radius; ++i) {
      const glm::ivec3 v = voxel + i * t + j * b;
      const glm::ivec3 l = v - slot * 16;
      size_t n;
      if (glm::all(glm::greaterThanEqual(l, glm::ivec3(0))) &&
          glm::all(glm::lessThan(l, glm::ivec3(16))))
        n = table.at(shared::faceLightTexel(l.x + 16 * l.y + 256 * l.z, face));
      else
        n = c.faces.find(v, face);
      if (n == kNoFace) continue;
      float w = c.weights.at(i + radius, j + radius, int(c.faces.occupancy(n)) - centre_occupancy);
      if (c.filter.range > 0.0f) {
        const float luminance = c.faces.luminance(n);
        const float scale =
            c.filter.range * c.relative_noise * std::max(centre_luminance, luminance);
        w *= gaussian(luminance - centre_luminance, scale + 1e-6f);
      }
      sum += double(w) * glm::dvec3(c.faces.value(n));
      weight_sum += double(w);
    }
  }
  return glm::vec3(sum / weight_sum);  // the centre itself has weight 1
}

}  // namespace

FaceLight filterFaceLight(const VoxelWorld& world, const FaceLight& light,
                          const FaceLightFilter& filter) {
  RDM_CHECK(filter.sigma > 0.0f && filter.range >= 0.0f && filter.occupancy >= 0.0f);
  if (filter.radius <= 0) return light;
  const FlatFaces faces(world, light, filter.threads);
  const StaticWeights weights(filter);
  const FilterContext context{faces, filter, weights,
                              1.0f / std::sqrt(float(std::max<uint32_t>(light.spp, 1)))};
  FaceLight out = light;
  ParallelOptions parallel;
  parallel.threads = filter.threads;
  parallelFor(light.slots.size(), parallel, [&](size_t r) {
    if (!faces.current(r)) return true;
    thread_local SlotTable table;  // a worker's, so each slot's set-up costs its faces only
    const FaceLightSlot& s = light.slots[r];
    table.set(s, faces.first(r));
    for (size_t i = 0; i < s.faces.size(); ++i) {
      out.slots[r].light[i] =
          filteredFace(context, table, s.slot, faceVoxel(s.slot, s.faces[i]),
                       int(s.faces[i] % shared::kFaceCount), faces.first(r) + i);
    }
    table.clear(s);
    return true;
  });
  return out;
}

}  // namespace rdm
