// Resources shared by the viewer's shaders. Every convention (face frames, hemi-oct,
// material byte, sizes) comes from shaders/shared/rdm_shared.h; this file only declares
// the bindings. Layouts mirror viewer/renderer/gpu_layout.h (std140 / std430).
#ifndef VIEWER_COMMON_GLSL
#define VIEWER_COMMON_GLSL

#extension GL_GOOGLE_include_directive : require
#include "rdm_shared.h"

// Term switches (FrameUniforms.grid_size.w), mirrored by viewer::Term in gpu_layout.h.
const int kTermRdm = 1;           // indirect light from the RDMs; off: docs/spec.md section 7's flat ambient
const int kTermDiffuse = 2;       // indirect diffuse
const int kTermSpecular = 4;      // indirect specular
const int kTermSun = 8;           // direct sun (GGX + Lambert)
const int kTermShadows = 16;      // shadow map visibility for the sun
const int kTermEmission = 32;     // voxel emission
const int kTermBackground = 64;   // sky and sun disc behind the geometry
const int kTermInBlock = 128;     // sharp reflections walk the near voxels first (near_voxels.glsl)
const int kTermFaceLight = 256;   // diffuse from the per-voxel-face light where baked (face_light.glsl)
const int kTermBlockBlend = 512;  // specular RDM lookups blend across block boundaries (rdm_lookup.glsl)
const int kTermFaceLightFilter = 1024;  // the face light's filtered values (face_light.glsl)

layout(set = 0, binding = 0, std140) uniform FrameUniforms {
  mat4 view_proj;
  mat4 light_view_proj;
  vec4 camera_position;  // xyz; w: tan(fov_y / 2)
  vec4 camera_forward;   // xyz; w: aspect W / H
  vec4 camera_right;     // xyz (docs/spec.md section 4 camera basis)
  vec4 camera_up;        // xyz
  vec4 sun_direction;    // xyz unit, towards the sun; w: 1 when the scene has a sun
  vec4 sun_irradiance;   // rgb; w: sin(theta), the disc's alpha floor
  vec4 sun_radiance;     // rgb = irradiance / Omega; w: 4 sin^2(theta / 2)
  vec4 sky_zenith;
  vec4 sky_horizon;
  vec4 sky_ground;
  vec4 ambient;          // rgb; w: emission_scale
  ivec4 grid_size;       // xyz slots; w: term bits
  vec4 viewport;         // width, height, shadow texel size in world units, atlas page count
  vec4 atlas_size;       // atlas array width, height (texels), 1/width, 1/height
  vec4 jitter;           // xy: the frame's sample offset from the pixel centre (pixels)
} frame;

bool termOn(int bit) { return (frame.grid_size.w & bit) != 0; }

vec3 skyRadiance(vec3 d) {
  return skyGradient(frame.sky_zenith.rgb, frame.sky_horizon.rgb, frame.sky_ground.rgb, d);
}

#endif  // VIEWER_COMMON_GLSL
