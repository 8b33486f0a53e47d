#include <algorithm>
#include <sstream>

#include "rdm/bake/rdm_list.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

bool canonicalLess(const RdmId& a, const RdmId& b) {
  if (a.size != b.size) return a.size > b.size;
  for (int i = 0; i < 3; ++i) {
    if (a.slot[i] != b.slot[i]) return a.slot[i] < b.slot[i];
  }
  return a.level < b.level;
}

namespace {

// The levels that have an RDM in a non-empty slot: level 7 and each roughness level present.
uint8_t rdmLevels(const VoxelWorld& world, int32_t block) {
  return world.blocks[size_t(block)].level_mask | uint8_t(1u << shared::kDiffuseLevel);
}

}  // namespace

size_t countRdms(const VoxelWorld& world) {
  size_t n = 0;
  for (int32_t b : world.slots) {
    if (b >= 0) n += size_t(__builtin_popcount(rdmLevels(world, b)));
  }
  return n;
}

std::vector<RdmId> listRdms(const VoxelWorld& world, const BakeSettings& settings) {
  std::vector<RdmId> out;
  out.reserve(countRdms(world));
  for (int k = 0; k < world.size.z; ++k)
    for (int j = 0; j < world.size.y; ++j)
      for (int i = 0; i < world.size.x; ++i) {
        const int32_t b = world.blockAt({i, j, k});
        if (b < 0) continue;
        const uint8_t levels = rdmLevels(world, b);
        for (int level = 0; level < shared::kLevelCount; ++level) {
          if (levels & (1u << level)) {
            out.push_back(
                {{i, j, k}, level, shared::hemisphereSize(level, settings.max_hemisphere)});
          }
        }
      }
  std::sort(out.begin(), out.end(), canonicalLess);
  return out;
}

bool faceSkipped(const VoxelWorld& world, const glm::ivec3& slot, int face) {
  glm::ivec3 neighbour = slot + shared::faceNormal(face);
  int32_t b = world.blockAt(neighbour);
  return b >= 0 && world.blocks[b].face_full[face ^ 1];
}

int radianceMapLevel(const VoxelWorld& world, const BakeSettings& settings,
                     const glm::ivec3& slot) {
  if (settings.estimator != Estimator::kPrefiltered) return -1;
  const uint8_t rough = world.blocks[size_t(world.blockAt(slot))].level_mask & 0x7fu;
  return rough == 0 ? -1 : __builtin_ctz(rough);
}

EffectSet sceneEffects(const VoxelWorld& world) {
  EffectSet e;
  e.sun = world.sun.present;
  e.emitters = !world.emitters.empty();
  e.glass = hasGlass(world);
  for (const OrientedBlock& b : world.blocks) {
    e.levels |= b.level_mask;
    for (uint8_t v : b.voxels) e.metals = e.metals || (v && world.materials[v].metallic > 0.0f);
  }
  return e;
}

std::string EffectSet::describeSimulated() const {
  std::ostringstream os;
  os << "sky";
  if (sun) os << ", sun (next-event estimation, shadow rays)";
  if (emitters) os << ", emissive voxels (next-event estimation with MIS)";
  if (metals) os << ", metals";
  if (glass) os << ", glass (refraction, Fresnel; shadow rays cross it straight)";
  os << "; roughness levels";
  for (int r = 0; r < 8; ++r) {
    if (levels & (1 << r)) os << " " << r;
  }
  return os.str();
}

std::string EffectSet::describeSkipped() const {
  std::ostringstream os;
  const char* sep = "";
  if (!sun) os << sep << "sun (no shadow rays)", sep = ", ";
  if (!emitters) os << sep << "emitters (no light sampling)", sep = ", ";
  if (!metals) os << sep << "metals", sep = ", ";
  if (!glass) os << sep << "glass", sep = ", ";
  bool any_level = false;
  for (int r = 0; r < 7; ++r) {
    if (!(levels & (1 << r))) {
      os << (any_level ? " " : std::string(sep) + "roughness levels ") << r;
      any_level = true;
    }
  }
  return os.str().empty() ? "nothing" : os.str();
}

}  // namespace rdm
