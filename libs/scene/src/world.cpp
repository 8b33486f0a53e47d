#include "rdm/scene/world.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

using glm::ivec3;

OrientedBlock orientBlock(const Block& block, int rot, const VoxelWorld& world) {
  OrientedBlock out;
  out.rot = rot;
  out.voxels = orientedVoxels(block, rot);
  for (uint8_t index : out.voxels) {
    if (!index) continue;
    ++out.solid_count;
    out.level_mask |= uint8_t(1u << world.materials[index].roughness);
  }
  for (int f = 0; f < 6; ++f) {
    int axis = f / 2, layer = f % 2 == 0 ? 15 : 0;
    bool full = true;
    for (int a = 0; a < 16 && full; ++a)
      for (int b = 0; b < 16 && full; ++b) {
        ivec3 p(0);
        p[axis] = layer;
        p[(axis + 1) % 3] = a;
        p[(axis + 2) % 3] = b;
        full = out.voxels[p.x + 16 * p.y + 256 * p.z] != 0;
      }
    out.face_full[f] = full;
  }
  return out;
}

void buildMaterials(const Scene& scene, VoxelWorld& world) {
  for (size_t i = 0; i < scene.palette.size(); ++i) {
    const PaletteEntry& e = scene.palette[i];
    Material& m = world.materials[i + 1];
    m.base_color =
        glm::vec3(srgbToLinear(e.color[0]), srgbToLinear(e.color[1]), srgbToLinear(e.color[2]));
    m.metallic = shared::metallicFactor(e.metallic);
    m.roughness = e.roughness;
    m.alpha = shared::roughnessAlpha(e.roughness);
    m.f0 = shared::materialF0(m.base_color, m.metallic);
    m.emission = m.base_color * float(double(e.emission) / 3.0 * scene.emission_scale);
    m.emissive =
        e.emission > 0 && scene.emission_scale > 0 && glm::dot(m.emission, m.emission) > 0.0f;
    m.transmission = float(e.transmission);
    m.ior = float(e.ior);
  }
}

// Each oriented block once: does it hold an emissive voxel? A world of a million placements
// then scans only the slots whose block can emit (the same emitters in the same order).
std::vector<bool> emissiveBlocks(const VoxelWorld& world) {
  std::vector<bool> out(world.blocks.size(), false);
  for (size_t b = 0; b < world.blocks.size(); ++b)
    for (uint8_t voxel : world.blocks[b].voxels)
      if (voxel && world.materials[voxel].emissive) {
        out[b] = true;
        break;
      }
  return out;
}

void buildEmitters(VoxelWorld& world) {
  std::vector<float> weights;
  const std::vector<bool> emissive = emissiveBlocks(world);
  for (int sk = 0; sk < world.size.z; ++sk)
    for (int sj = 0; sj < world.size.y; ++sj)
      for (int si = 0; si < world.size.x; ++si) {
        int32_t b = world.blockAt({si, sj, sk});
        if (b < 0 || !emissive[size_t(b)]) continue;
        for (int v = 0; v < 4096; ++v) {
          const Material& m = world.materials[world.blocks[b].voxels[v]];
          if (!world.blocks[b].voxels[v] || !m.emissive) continue;
          ivec3 voxel = ivec3(si, sj, sk) * 16 + ivec3(v % 16, (v / 16) % 16, v / 256);
          for (int f = 0; f < 6; ++f) {
            if (world.voxelAt(voxel + shared::faceNormal(f))) continue;
            world.emitters.emitters.push_back({voxel, f, m.emission});
            weights.push_back(std::max(luminance(m.emission), 1e-20f));
          }
        }
      }
  double total = 0.0, running = 0.0;
  for (float w : weights) total += w;
  for (float w : weights) {
    running += w;
    world.emitters.cdf.push_back(float(running / total));
  }
  if (!world.emitters.cdf.empty()) world.emitters.cdf.back() = 1.0f;
  world.emitters.total_luminance = float(total);
  if (world.emitters.empty()) return;
  std::vector<uint32_t>& first = world.emitters.slot_first;
  first.assign(world.slots.size() + 1, 0);
  for (const Emitter& e : world.emitters.emitters)
    ++first[size_t(world.slotLinear(e.voxel >> 4)) + 1];
  for (size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
}

}  // namespace

bool hasGlass(const VoxelWorld& world) {
  if (std::none_of(world.materials.begin(), world.materials.end(),
                   [](const Material& m) { return m.transmission > 0.0f; }))
    return false;
  for (const OrientedBlock& b : world.blocks)
    for (uint8_t v : b.voxels)
      if (v && world.materials[v].transmission > 0.0f) return true;
  return false;
}

std::array<uint8_t, 4096> orientedVoxels(const Block& block, int rot) {
  std::array<uint8_t, 4096> out{};
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const uint8_t index = block.voxels[x + 16 * y + 256 * z];
        if (!index) continue;
        const ivec3 p = shared::orientVoxel(rot, ivec3(x, y, z));
        out[p.x + 16 * p.y + 256 * p.z] = index;
      }
  return out;
}

float srgbToLinear(int value) {
  double c = value / 255.0;
  return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

BrickMasks brickMasks(const OrientedBlock& block) {
  BrickMasks out;
  for (int v = 0; v < 4096; ++v) {
    if (!block.voxels[v]) continue;
    const int x = v % 16, y = (v / 16) % 16, z = v / 256;
    const int brick = x / 4 | (y / 4) << 2 | (z / 4) << 4;
    out.voxels[brick] |= uint64_t(1) << (x % 4 | (y % 4) << 2 | (z % 4) << 4);
    out.bricks |= uint64_t(1) << brick;
  }
  return out;
}

uint8_t VoxelWorld::voxelAt(const ivec3& v) const {
  ivec3 extent = voxelExtent();
  if (v.x < 0 || v.y < 0 || v.z < 0 || v.x >= extent.x || v.y >= extent.y || v.z >= extent.z)
    return 0;
  int32_t b = slots[slotLinear(v >> 4)];
  if (b < 0) return 0;
  ivec3 l = v & 15;
  return blocks[b].voxels[l.x + 16 * l.y + 256 * l.z];
}

VoxelWorld buildWorld(const Scene& scene) {
  VoxelWorld world;
  world.size = ivec3(scene.size[0], scene.size[1], scene.size[2]);
  world.slots.assign(size_t(world.size.x) * world.size.y * world.size.z, -1);
  buildMaterials(scene, world);
  std::map<std::pair<std::string, int>, int32_t> oriented;
  for (const Placement& p : scene.placements) {
    auto key = std::make_pair(p.block, p.rot);
    auto it = oriented.find(key);
    if (it == oriented.end()) {
      OrientedBlock ob = orientBlock(scene.blocks.at(p.block), p.rot, world);
      ob.name = p.block;
      int32_t index = ob.solid_count > 0 ? int32_t(world.blocks.size()) : -1;
      if (index >= 0) world.blocks.push_back(std::move(ob));
      it = oriented.emplace(key, index).first;
    }
    world.slots[world.slotLinear(ivec3(p.at[0], p.at[1], p.at[2]))] = it->second;
  }
  for (const OrientedBlock& b : world.blocks) world.occupancy.push_back(brickMasks(b));
  world.slot_steps.resize(world.slots.size());
  for (int z = 0; z < world.size.z; ++z)
    for (int y = 0; y < world.size.y; ++y)
      for (int x = 0; x < world.size.x; ++x) {
        const ivec3 group = ivec3(x, y, z) & ~1;
        bool group_empty = true;
        for (int k = 0; k < 8; ++k) {
          const ivec3 s = group + ivec3(k & 1, k >> 1 & 1, k >> 2);
          group_empty = group_empty && world.blockAt(s) < 0;
        }
        const int32_t block = world.slots[size_t(world.slotLinear({x, y, z}))];
        world.slot_steps[size_t(world.slotLinear({x, y, z}))] =
            block >= 0 ? block * kOccupancyWords : (group_empty ? kEmptySlotGroup : kEmptySlot);
      }
  world.sky = {glm::vec3(scene.sky.zenith), glm::vec3(scene.sky.horizon),
               glm::vec3(scene.sky.ground)};
  if (scene.sun)
    world.sun =
        makeSunLight(scene.sun->direction, scene.sun->irradiance, scene.sun->angular_radius_deg);
  world.ambient = glm::vec3(scene.ambient);
  buildEmitters(world);
  return world;
}

}  // namespace rdm
