// Direction sampling and frames. Directions are unit vectors; pdfs are per steradian. The
// math is shaders/shared/rdm_shared.h's, shared with the Vulkan kernel and the viewer.
#pragma once

#include <glm/glm.hpp>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

constexpr float kPi = shared::kPiF;

struct Frame {
  glm::vec3 t, b, n;  // right-handed: t x b = n
  glm::vec3 toLocal(const glm::vec3& v) const { return shared::frameToLocal({t, b, n}, v); }
  glm::vec3 toWorld(const glm::vec3& v) const { return shared::frameToWorld({t, b, n}, v); }
};

// Orthonormal basis around a unit vector (Duff et al. 2017), continuous except at n.z = -0.
inline Frame frameAround(const glm::vec3& n) {
  const shared::ShFrame f = shared::frameAroundDir(n);
  return {f.t, f.b, f.n};
}

inline glm::vec3 sampleCosineHemisphere(float u0, float u1) {
  return shared::sampleCosineDir(u0, u1);
}

// Uniform direction in the cone of half-angle theta around +z, given 1 - cos(theta)
// (so tiny cones keep full precision).
inline glm::vec3 sampleUniformCone(float one_minus_cos_max, float u0, float u1) {
  return shared::sampleConeDir(one_minus_cos_max, u0, u1);
}

}  // namespace rdm
