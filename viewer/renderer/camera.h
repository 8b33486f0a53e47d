// View and light transforms matching docs/spec.md section 4's camera rays: the rasterised pixel
// (x, y) sees exactly the direction rdm::cameraRayDirection gives for (x + 0.5, y + 0.5).
#pragma once

#include <glm/glm.hpp>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"

namespace rdm::viewer {

struct CameraBasis {
  glm::vec3 position{0.0f}, forward{0.0f, 0.0f, 1.0f}, right{1.0f, 0.0f, 0.0f},
      up{0.0f, 1.0f, 0.0f};
  float tan_half_fov = 0.5f;
};

inline constexpr float kNearPlane = 0.01f;
inline constexpr float kFarPlane = 2000.0f;

// forward = normalize(target - position), right = normalize(forward x Y), up = right x
// forward. Errors when forward is parallel to Y (docs/spec.md section 4).
Expected<CameraBasis> cameraBasis(const Camera& camera);

// Vulkan clip space (y down, depth 0..1): x_ndc = a / (tan W/H), y_ndc = -b / tan in the
// the spec's (a, b) pixel parametrisation.
glm::mat4 viewProjection(const CameraBasis& basis, float aspect);

// Orthographic view of the whole grid [0, size] from the sun (`to_sun` unit). Writes the
// shadow map's texel size in world units to `texel_world`.
glm::mat4 sunViewProjection(const glm::vec3& to_sun, const glm::ivec3& grid_size, int map_size,
                            float* texel_world);

}  // namespace rdm::viewer
