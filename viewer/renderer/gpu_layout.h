// Host mirrors of the shader interfaces in viewer/shaders/viewer_common.glsl and
// rdm_lookup.glsl (std140 uniform block, std430 storage buffers). Only vec4-sized members,
// so the C++ and GLSL layouts agree without padding rules.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "rdm/rdm_shared_cpp.h"

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
  kTermAll = 127,        // docs/spec.md section 6's terms
  // Opt-in, measured only indicatively (docs/results.md section 1b): sharp reflections walk
  // the near voxels before the RDM (viewer/shaders/near_voxels.glsl).
  kTermInBlock = 128,
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

// Per slot, linear index i + X (j + Y k). Per level l, the face tiles of its map:
// rdm[2l] = (hemisphere S or 0, pages, tile 0, tile 1), rdm[2l+1] = (tiles 2..5), where
// pages holds 5 bits per face (face f at bit 5f, kNoTilePage: not stored) and a tile is
// x | y << 16 (x, y < kMaxPageSize = 2^14).
constexpr int kNoTilePage = 31;
struct SlotInfo {
  glm::ivec4 header{-1, 0, 0, 0};  // oriented block, diffuse-usable faces, skipped faces, 0
  glm::ivec4 rdm[2 * shared::kLevelCount]{};
};
static_assert(sizeof(SlotInfo) == 16 * 17);

}  // namespace rdm::viewer
