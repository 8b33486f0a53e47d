// Orbit and fly cameras for the window. Both produce an rdm::Camera (position, target,
// fov), so the renderer's docs/spec.md section 4 camera convention applies unchanged. Pitch stays
// inside
// +-89 degrees: forward is never parallel to Y.
#pragma once

#include <glm/glm.hpp>

#include "rdm/scene/scene.h"

namespace rdm::viewer {

enum class CameraMode { kOrbit, kFly };

struct CameraInput {
  glm::vec2 rotate{0.0f};  // pixels dragged with the rotate button
  glm::vec2 pan{0.0f};     // pixels dragged with the pan button
  float scroll = 0.0f;     // wheel steps
  glm::vec3 move{0.0f};    // fly: right, up, forward in -1..1
  float dt = 0.0f;         // seconds since the last update
};

class CameraController {
 public:
  void reset(const Camera& camera);
  void setMode(CameraMode mode) { mode_ = mode; }
  CameraMode mode() const { return mode_; }
  void update(const CameraInput& input);
  Camera camera() const;

 private:
  glm::vec3 forward() const;

  CameraMode mode_ = CameraMode::kOrbit;
  glm::vec3 target_{0.0f};    // orbit centre
  glm::vec3 position_{0.0f};  // fly position
  float distance_ = 5.0f;
  float yaw_ = 0.0f, pitch_ = 0.0f;  // radians; forward = (cos p sin y, sin p, cos p cos y)
  double fov_deg_ = 50.0;
};

}  // namespace rdm::viewer
