#include "camera_controller.h"

#include <algorithm>
#include <cmath>

namespace rdm::viewer {
namespace {

constexpr float kMaxPitch = 1.55f;  // ~89 degrees
constexpr float kRadiansPerPixel = 0.005f;
constexpr float kFlySpeed = 4.0f;  // world units per second

}  // namespace

void CameraController::reset(const Camera& camera) {
  const glm::vec3 p(camera.position), t(camera.target);
  const glm::vec3 d = t - p;
  distance_ = std::max(glm::length(d), 1e-3f);
  const glm::vec3 f = d / distance_;
  pitch_ = std::clamp(std::asin(std::clamp(f.y, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
  yaw_ = std::atan2(f.x, f.z);
  target_ = t, position_ = p;
  fov_deg_ = camera.fov_deg;
}

glm::vec3 CameraController::forward() const {
  return {std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_), std::cos(pitch_) * std::cos(yaw_)};
}

void CameraController::update(const CameraInput& in) {
  yaw_ -= in.rotate.x * kRadiansPerPixel;
  pitch_ = std::clamp(pitch_ - in.rotate.y * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
  const glm::vec3 f = forward();
  const glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0.0f, 1.0f, 0.0f)));
  const glm::vec3 up = glm::cross(right, f);
  if (mode_ == CameraMode::kOrbit) {
    distance_ = std::clamp(distance_ * std::pow(0.9f, in.scroll), 0.05f, 1000.0f);
    target_ += (-in.pan.x * right + in.pan.y * up) * (distance_ * 0.002f);
    position_ = target_ - f * distance_;
  } else {
    const float speed = kFlySpeed * std::pow(1.25f, in.scroll);
    position_ += (in.move.x * right + in.move.y * up + in.move.z * f) * (speed * in.dt);
    position_ += (-in.pan.x * right + in.pan.y * up) * 0.01f;
    target_ = position_ + f * distance_;
  }
}

Camera CameraController::camera() const {
  Camera c;
  c.position = glm::dvec3(position_);
  c.target = glm::dvec3(position_ + forward() * distance_);
  c.fov_deg = fov_deg_;
  return c;
}

}  // namespace rdm::viewer
