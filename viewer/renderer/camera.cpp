#include "camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rdm::viewer {

Expected<CameraBasis> cameraBasis(const Camera& camera) {
  const glm::dvec3 f = camera.target - camera.position;
  const glm::dvec3 r = glm::cross(f, glm::dvec3(0.0, 1.0, 0.0));
  if (glm::length(f) <= 0.0 || glm::length(r) <= 1e-12 * glm::length(f)) {
    return Status::error(
        "camera looks along the Y axis (docs/spec.md section 4 needs forward not parallel to +Y)");
  }
  CameraBasis b;
  b.position = glm::vec3(camera.position);
  b.forward = glm::vec3(glm::normalize(f));
  b.right = glm::normalize(glm::cross(b.forward, glm::vec3(0.0f, 1.0f, 0.0f)));
  b.up = glm::cross(b.right, b.forward);
  b.tan_half_fov = float(std::tan(camera.fov_deg * 0.5 * std::numbers::pi / 180.0));
  return b;
}

glm::mat4 viewProjection(const CameraBasis& b, float aspect) {
  const float sx = 1.0f / (b.tan_half_fov * aspect), sy = 1.0f / b.tan_half_fov;
  const float za = kFarPlane / (kFarPlane - kNearPlane),
              zb = -kFarPlane * kNearPlane / (kFarPlane - kNearPlane);
  glm::mat4 m(0.0f);  // m[column][row]
  const glm::vec4 rows[4] = {
      glm::vec4(sx * b.right, -sx * glm::dot(b.right, b.position)),
      glm::vec4(-sy * b.up, sy * glm::dot(b.up, b.position)),
      glm::vec4(za * b.forward, -za * glm::dot(b.forward, b.position) + zb),
      glm::vec4(b.forward, -glm::dot(b.forward, b.position)),
  };
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[c][r] = rows[r][c];
  return m;
}

glm::mat4 sunViewProjection(const glm::vec3& to_sun, const glm::ivec3& grid_size, int map_size,
                            float* texel_world) {
  const glm::vec3 z = -to_sun;  // the light looks along -to_sun
  const glm::vec3 helper =
      std::abs(z.y) < 0.99f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 x = glm::normalize(glm::cross(helper, z));
  const glm::vec3 y = glm::cross(z, x);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p(corner & 1 ? grid_size.x : 0, corner & 2 ? grid_size.y : 0,
                      corner & 4 ? grid_size.z : 0);
    const glm::vec3 q(glm::dot(x, p), glm::dot(y, p), glm::dot(z, p));
    lo = glm::min(lo, q), hi = glm::max(hi, q);
  }
  lo -= glm::vec3(0.5f), hi += glm::vec3(0.5f);
  const glm::vec3 scale =
      glm::vec3(2.0f / (hi.x - lo.x), 2.0f / (hi.y - lo.y), 1.0f / (hi.z - lo.z));
  const glm::vec4 rows[4] = {
      glm::vec4(scale.x * x, -scale.x * lo.x - 1.0f),
      glm::vec4(scale.y * y, -scale.y * lo.y - 1.0f),
      glm::vec4(scale.z * z, -scale.z * lo.z),
      glm::vec4(0.0f, 0.0f, 0.0f, 1.0f),
  };
  glm::mat4 m(0.0f);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[c][r] = rows[r][c];
  if (texel_world) *texel_world = std::max(hi.x - lo.x, hi.y - lo.y) / float(map_size);
  return m;
}

}  // namespace rdm::viewer
