#include "rdm/atlas/bake_estimate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

// packCanonical keeps a layout per candidate page width (up to one per column of the smallest
// tile); above this many RDMs the pages are counted from the texel area instead, so an
// admission check never holds more than a few tens of MB.
constexpr size_t kExactPackRdms = 4096;
// Texel area over page area of packCanonical's layouts above kExactPackRdms (chess and
// island pack at 0.97 to 1.0; the slack covers the last page's ragged row).
constexpr double kPackedOccupancy = 0.95;

// A daemon job's memory. Texels are held only for the RDMs in flight (at most one per
// roughness level of the slots the workers bake) and the page being written, as in
// `rdm bake`; per RDM stay its plan, unit, origin and index entries (kDaemonBytesPerRdm) and
// its slot sets as runs (slotSetBytesPerRdm); per RDM image texel, a margin
// for the preview pass of a progressive job (RDMs at half size, held and published: 11
// bytes) and the radiance maps of the slots in flight. VmHWM over one `rdm serve` job
// (scripts/bench/daemon_memory.sh, 2 threads, 2026-12-05) over the RSS before the job
// (61 MB), against this model; the previous one (every texel held, 64 KB per RDM) said
// 141 to 2386 MB for the generated worlds:
//   scene                         RDMs  max_hemisphere  measured  this model
//   chess                          162       64           38 MB      56 MB
//   chess                          162      128          103 MB     192 MB
//   generated                      500      128           22 MB      42 MB
//   generated                     2000       64           77 MB     166 MB
//   generated                     5000       16           68 MB     151 MB
//   generated                    20001       16          313 MB     606 MB
// (The model then held 12 KB per RDM for entries and sets together; the sets' term, below,
// gives 8.3-14.5 KB on these rows.)
constexpr uint64_t kDaemonBytesPerRdm = 8 << 10;
// Slot-set bytes per RDM per slot of the grid's largest extent: `rdm bake`'s peak RSS with
// and without --no-slot-sets on bench/gen_world.py's worlds (2026-12-07, --backend cpu):
// 5,001 RDMs (82 slots across) 13.1 MB, 2.6 KB an RDM, 32 bytes a slot of extent; 20,001
// RDMs (163 across) 98 MB, 4.9 KB, 30 bytes. 40 is taken.
constexpr uint64_t kSlotSetBytesPerRdmPerExtent = 40;
constexpr uint64_t kDaemonBytesPerTexel = 20;
constexpr uint64_t kDaemonRdmsInFlightPerThread = 8;
// `rdm bake`: texels of an RDM in flight (RGBZ + standard error, 7 floats), RDMs in flight
// per thread, and the index entry (id, tiles, slot key) of every RDM.
constexpr uint64_t kCliBytesPerTexel = 28;
constexpr uint64_t kCliRdmsInFlightPerThread = 2;
constexpr uint64_t kCliBytesPerRdm = 100;
// Rays per traced texel sample: 1 + 0.6 per bounce fits rdm bake's BakeReport rays over
// traced samples within 15 % on random-voxel scenes at 2 and 3 bounces (1.9, 2.7). Rays per
// CPU-second measured with `rdm bake --threads 1 --spp 16 --max-bounces 4
// --max-hemisphere 32` (BakeReport rays / cpu_seconds) on this project's shared 2-core
// x86-64 machine: chess 4.5 M (naive) and 5.1 M (prefiltered), island 3.2 M and 3.5 M;
// daemon jobs on dense random-voxel scenes 1.4 M per second of unit wall time. 3 M is taken.
constexpr double kRaysPerSampleBase = 1.0;
constexpr double kRaysPerSamplePerBounce = 0.6;
constexpr double kRaysPerCpuSecond = 3.0e6;

uint64_t bytesPerAtlasTexel(RadianceFormat radiance) {
  switch (radiance) {
    case RadianceFormat::kHalf:
      return 10;  // half R, G, B + float Z
    case RadianceFormat::kBc6h:
      return 3;  // a BC6H block is 1 byte a texel, + half Z
    case RadianceFormat::kFloat32:
      break;
  }
  return 16;  // 4 floats
}

int storedFaceCount(const VoxelWorld& world, const glm::ivec3& slot) {
  int n = 0;
  for (int f = 0; f < 6; ++f) n += faceSkipped(world, slot, f) ? 0 : 1;
  return n;
}

// Texels the path tracer traces for one slot's face, per the estimator (docs/spec.md 3.1): the
// prefiltered one traces the mirror level and one radiance map at the finest rough level and
// derives the other levels; the naive one traces every level.
uint64_t tracedFaceTexels(uint8_t levels, const BakeSettings& settings) {
  uint64_t texels = 0;
  const uint8_t rough = levels & 0x7eu;  // levels 1..6
  const bool prefiltered = settings.estimator == Estimator::kPrefiltered && rough != 0;
  for (int level = 0; level < shared::kLevelCount; ++level) {
    if (!(levels >> level & 1u)) continue;
    const uint64_t s = uint64_t(shared::hemisphereSize(level, settings.max_hemisphere));
    const bool derived = prefiltered && level > 0 && level != __builtin_ctz(rough);
    texels += derived ? 0 : s * s;
  }
  return texels;
}

// Pages and pixel bytes of the canonical atlas of `world`'s RDMs.
void estimateAtlas(const VoxelWorld& world, const BakeSettings& settings, RadianceFormat radiance,
                   BakeEstimate& e, uint64_t& largest_page) {
  const uint64_t per_texel = bytesPerAtlasTexel(radiance);
  if (e.rdms == 0) return;
  if (e.rdms <= kExactPackRdms) {
    const AtlasLayout layout =
        packCanonical(listRdms(world, settings), storedFacesOf(world), radiance);
    e.pages = int(layout.pages.size());
    for (const AtlasPage& p : layout.pages) {
      const uint64_t texels = uint64_t(p.width) * uint64_t(p.height);
      e.atlas_bytes += texels * per_texel;
      largest_page = std::max(largest_page, texels);
    }
    return;
  }
  const double page_texels = double(kPackedPageSize) * double(kPackedPageSize);
  const double area = double(e.texels) / kPackedOccupancy;
  e.pages = std::max(1, int(std::ceil(area / page_texels)));
  e.atlas_bytes = uint64_t(area) * per_texel;
  largest_page = uint64_t(std::min(area, page_texels));
}

// Emissive voxel faces of `block` not covered by a solid voxel of the same block: at most
// the faces an EmitterList holds for one placement of it.
uint64_t openEmissiveFaces(const Block& block, const std::vector<PaletteEntry>& palette) {
  auto solid = [&](int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x > 15 || y > 15 || z > 15) return false;
    return block.voxels[size_t(x + 16 * y + 256 * z)] != 0;
  };
  uint64_t faces = 0;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const int v = block.voxels[size_t(x + 16 * y + 256 * z)];
        if (v == 0 || v > int(palette.size()) || palette[size_t(v - 1)].emission == 0) continue;
        faces += !solid(x - 1, y, z) + !solid(x + 1, y, z) + !solid(x, y - 1, z) +
                 !solid(x, y + 1, z) + !solid(x, y, z - 1) + !solid(x, y, z + 1);
      }
  return faces;
}

constexpr uint64_t kBytesPerOrientedBlock = sizeof(OrientedBlock) + sizeof(BrickMasks);
constexpr uint64_t kBytesPerSlot = 2 * sizeof(int32_t);                 // slots and slot_steps
constexpr uint64_t kBytesPerEmitter = sizeof(Emitter) + sizeof(float);  // with its CDF entry

}  // namespace

uint64_t slotSetBytesPerRdm(const VoxelWorld& world) {
  const int extent = std::max(world.size.x, std::max(world.size.y, world.size.z));
  return kSlotSetBytesPerRdmPerExtent * uint64_t(std::max(extent, 1));
}

uint64_t worldBytes(const VoxelWorld& world) {
  return uint64_t(world.slots.size() + world.slot_steps.size()) * sizeof(int32_t) +
         uint64_t(world.blocks.size()) * kBytesPerOrientedBlock +
         uint64_t(world.emitters.emitters.size()) * kBytesPerEmitter;
}

BakeEstimate estimateBake(const VoxelWorld& world, const BakeSettings& settings,
                          RadianceFormat radiance, int threads, const BakeExtras& extras) {
  BakeEstimate e;
  e.world_bytes = worldBytes(world);
  uint64_t traced = 0, rdm_image_texels = 0;
  int largest_size = 0;
  for (int k = 0; k < world.size.z; ++k)
    for (int j = 0; j < world.size.y; ++j)
      for (int i = 0; i < world.size.x; ++i) {
        const int32_t b = world.blockAt({i, j, k});
        if (b < 0) continue;
        ++e.blocks;
        const uint8_t levels =
            world.blocks[size_t(b)].level_mask | uint8_t(1u << shared::kDiffuseLevel);
        const uint64_t faces = uint64_t(storedFaceCount(world, {i, j, k}));
        for (int level = 0; level < shared::kLevelCount; ++level) {
          if (!(levels >> level & 1u)) continue;
          const int s = shared::hemisphereSize(level, settings.max_hemisphere);
          ++e.rdms;
          e.texels += faces * uint64_t(s) * uint64_t(s);
          rdm_image_texels += 6 * uint64_t(s) * uint64_t(s);
          largest_size = std::max(largest_size, s);
        }
        traced += faces * tracedFaceTexels(levels, settings);
      }
  uint64_t largest_page = 0;
  estimateAtlas(world, settings, radiance, e, largest_page);
  const uint64_t float_page_bytes = largest_page * 16;  // a page is assembled in float32
  const uint64_t largest_rdm = 6 * uint64_t(largest_size) * uint64_t(largest_size);
  e.peak_memory_bytes =
      e.world_bytes +
      kCliRdmsInFlightPerThread * uint64_t(std::max(1, threads)) * largest_rdm * kCliBytesPerTexel +
      float_page_bytes +
      uint64_t(e.rdms) * (kCliBytesPerRdm + (extras.slot_sets ? slotSetBytesPerRdm(world) : 0));
  e.daemon_memory_bytes = e.world_bytes +
                          uint64_t(e.rdms) * (kDaemonBytesPerRdm + slotSetBytesPerRdm(world)) +
                          rdm_image_texels * kDaemonBytesPerTexel +
                          kDaemonRdmsInFlightPerThread * uint64_t(std::max(1, threads)) *
                              largest_rdm * kCliBytesPerTexel +
                          float_page_bytes;
  // units.log (7 floats a stored texel), the job's spill (7 floats an image texel; twice
  // when the denoiser writes its own), rdms.store (RGBZ floats) and the atlas.
  e.disk_bytes =
      e.texels * 28 + rdm_image_texels * ((extras.denoise ? 56 : 28) + 16) + e.atlas_bytes;
  const double rays_per_sample =
      kRaysPerSampleBase + kRaysPerSamplePerBounce * double(settings.max_bounces);
  e.cpu_seconds = double(traced) * double(settings.spp) * rays_per_sample / kRaysPerCpuSecond;
  return e;
}

SceneEstimate estimateScene(const Scene& scene) {
  SceneEstimate e;
  e.placements = scene.placements.size();
  std::set<std::pair<std::string, int>> oriented;
  std::map<std::string, std::pair<bool, uint64_t>> block_info;  // filled, open emissive faces
  for (const auto& [name, block] : scene.blocks) {
    const bool filled =
        std::any_of(block.voxels.begin(), block.voxels.end(), [](uint8_t v) { return v != 0; });
    block_info[name] = {filled, filled ? openEmissiveFaces(block, scene.palette) : 0};
  }
  uint64_t emitters = 0;
  for (const Placement& p : scene.placements) {
    const auto it = block_info.find(p.block);
    if (it == block_info.end() || !it->second.first) continue;
    ++e.filled_placements;
    emitters += it->second.second;
    oriented.insert({p.block, p.rot});
  }
  const uint64_t slots = uint64_t(std::max(scene.size[0], 0)) *
                         uint64_t(std::max(scene.size[1], 0)) *
                         uint64_t(std::max(scene.size[2], 0));
  e.world_bytes = slots * kBytesPerSlot + uint64_t(oriented.size()) * kBytesPerOrientedBlock +
                  emitters * kBytesPerEmitter;
  e.min_daemon_memory_bytes =
      e.world_bytes + uint64_t(e.filled_placements) * minDaemonBytesPerPlacement();
  return e;
}

uint64_t minDaemonBytesPerPlacement() {
  const uint64_t smallest_rdm_texels = 6 * 2 * 2;  // level 7 at S = 2
  return kDaemonBytesPerRdm + smallest_rdm_texels * kDaemonBytesPerTexel + kBytesPerSlot;
}

}  // namespace rdm
