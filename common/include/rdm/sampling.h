// Direction sampling and frames. Directions are unit vectors; pdfs are per steradian.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

namespace rdm {

constexpr float kPi = 3.14159265358979323846f;

struct Frame {
  glm::vec3 t, b, n;  // right-handed: t x b = n
  glm::vec3 toLocal(const glm::vec3& v) const {
    return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)};
  }
  glm::vec3 toWorld(const glm::vec3& v) const { return t * v.x + b * v.y + n * v.z; }
};

// Orthonormal basis around a unit vector (Duff et al. 2017), continuous except at n.z = -0.
inline Frame frameAround(const glm::vec3& n) {
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  return {glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x),
          glm::vec3(b, sign + n.y * n.y * a, -n.y), n};
}

inline glm::vec3 sampleCosineHemisphere(float u0, float u1) {
  float r = std::sqrt(u0), phi = 2.0f * kPi * u1;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u0))};
}

// Uniform direction in the cone of half-angle theta around +z, given 1 - cos(theta)
// (so tiny cones keep full precision).
inline glm::vec3 sampleUniformCone(float one_minus_cos_max, float u0, float u1) {
  float one_minus_cos = u0 * one_minus_cos_max;
  float sin_theta = std::sqrt(std::max(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
  float phi = 2.0f * kPi * u1;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), 1.0f - one_minus_cos};
}

}  // namespace rdm
