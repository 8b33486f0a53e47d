// Host mirrors of the shader interfaces in viewer/shaders/viewer_common.glsl and
// rdm_lookup.glsl (std140 uniform block, std430 storage buffers). Only vec4-sized members,
// so the C++ and GLSL layouts agree without padding rules.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm::viewer {

// Shading terms (FrameUniforms::grid_size.w). Every term can be switched independently.
enum Term : uint32_t {
  kTermRdm = 1,  // indirect light from the RDM atlas; off: docs/spec.md section 7's flat ambient
  kTermDiffuse = 2,      // indirect diffuse
  kTermSpecular = 4,     // indirect specular
  kTermSun = 8,          // direct sun
  kTermShadows = 16,     // shadow-mapped sun visibility
  kTermEmission = 32,    // voxel emission
  kTermBackground = 64,  // sky and sun disc
  kTermBase = 127,       // the thesis's terms (docs/spec.md section 6 without the two below)
  // Sharp reflections walk the near voxels before the RDM (viewer/shaders/near_voxels.glsl).
  kTermInBlock = 128,
  // Diffuse from the per-voxel-face light (face_light.bin) where it is loaded, the level-7
  // RDMs elsewhere (viewer/shaders/face_light.glsl). Without the file it changes nothing.
  kTermFaceLight = 256,
  // The specular RDM lookup blends the face-plane neighbours' RDMs near block boundaries
  // (viewer/shaders/rdm_lookup.glsl blendedRdmSpecular).
  kTermBlockBlend = 512,
  // The face light's values after filterFaceLight (rdm/bake/face_light_filter.h), with
  // kTermFaceLight; off: the baked values as they are.
  kTermFaceLightFilter = 1024,
  kTermDefault =
      kTermBase | kTermInBlock | kTermFaceLight | kTermBlockBlend | kTermFaceLightFilter,  // `all`
};

struct FrameUniforms {
  glm::mat4 view_proj;
  glm::mat4 light_view_proj;
  glm::vec4 camera_position;  // w: tan(fov_y / 2)
  glm::vec4 camera_forward;   // w: aspect
  glm::vec4 camera_right;
  glm::vec4 camera_up;
  glm::vec4 sun_direction;   // w: 1 when present
  glm::vec4 sun_irradiance;  // w: sin(theta)
  glm::vec4 sun_radiance;    // w: 4 sin^2(theta / 2)
  glm::vec4 sky_zenith;
  glm::vec4 sky_horizon;
  glm::vec4 sky_ground;
  glm::vec4 ambient;     // w: emission_scale
  glm::ivec4 grid_size;  // w: Term bits
  glm::vec4 viewport;    // width, height, shadow texel (world units), atlas pages
  glm::vec4 atlas_size;  // width, height, 1 / width, 1 / height
  glm::vec4 jitter;      // xy: sample offset from the pixel centre, pixels (pixelJitter)
};
static_assert(sizeof(FrameUniforms) == 2 * 64 + 15 * 16);

// Per slot, linear index i + X (j + Y k). header.w holds log2 of each level's hemisphere
// size, 4 bits per level (level l at bit 4l; 0: level absent). Face f of level l is word
// 6l + f of `tiles`: x / 2 | (y / 2) << 13 | page << 26, page kNoTilePage when the face is not
// stored (tile corners are even: multiples of S >= 2, below kMaxPageSize = 2^14).
constexpr int kNoTilePage = 63;
constexpr int kTileWords = 6 * shared::kLevelCount;
struct SlotInfo {
  glm::ivec4 header{-1, 0, 0, 0};  // oriented block, diffuse-usable faces, skipped faces, sizes
  glm::ivec4 tiles[kTileWords / 4]{};
};
static_assert(sizeof(SlotInfo) == 16 * 13);

}  // namespace rdm::viewer
