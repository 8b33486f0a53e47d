// Light sources of a scene (docs/spec.md sections 2 and 5): gradient sky, sun disc, emissive voxel
// faces. Constants derived in double on the host, used in float by the kernels.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

struct SkyLight {
  glm::vec3 zenith{0.0f}, horizon{0.0f}, ground{0.0f};
  glm::vec3 radiance(const glm::vec3& d) const {
    return shared::skyGradient(zenith, horizon, ground, d);
  }
};

struct SunLight {
  bool present = false;
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // unit, towards the sun
  glm::vec3 irradiance{0.0f};
  glm::vec3 radiance{0.0f};        // irradiance / omega
  float one_minus_cos_max = 0.0f;  // 2 sin^2(theta/2): cone sampling without cancellation
  float disc_c2 = 0.0f;            // 4 sin^2(theta/2): |d - s|^2 <= disc_c2 inside the disc
  float pdf = 0.0f;                // 1 / omega
  bool inDisc(const glm::vec3& d) const {
    glm::vec3 e = d - direction;
    return glm::dot(e, e) <= disc_c2;
  }
};
SunLight makeSunLight(const glm::dvec3& direction, const glm::dvec3& irradiance,
                      double angular_radius_deg);

// A face of an emissive voxel whose neighbour voxel is empty.
struct Emitter {
  glm::ivec3 voxel;  // global voxel coordinates
  int face;          // 0..5, docs/spec.md face order
  glm::vec3 radiance;
};

struct EmitterList {
  std::vector<Emitter> emitters;  // (slot, voxel index, face) order
  std::vector<float> cdf;         // normalised, by luminance
  float total_luminance = 0.0f;   // sum of the faces' radiance luminances
  // Emitters of the slot with linear index i: [slot_first[i], slot_first[i + 1]); slot count + 1
  // entries (docs/spec.md section 3.2's local emitter choice). Empty without emitters.
  std::vector<uint32_t> slot_first;
  bool empty() const { return emitters.empty(); }
  // Index picked by u in [0, 1); probability of each pick is pickPdf(index).
  int pick(float u) const;
};

float luminance(const glm::vec3& c);

}  // namespace rdm
