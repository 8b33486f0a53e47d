// Metallic-roughness BSDF of docs/spec.md section 5: Lambert (weighted by 1 - F) plus GGX with
// the height-correlated Smith G2 and Schlick F (F90 = 1); alpha = 0 is a true mirror.
// Every function works in the local frame of the surface (z = n) and stays finite for
// alpha in [0, 1] and any view with n.v > 0, however grazing. The math is
// shaders/shared/rdm_shared.h's (one definition for the CPU, the Vulkan kernel and the viewer).
#pragma once

#include <glm/glm.hpp>

#include "rdm/scene/world.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

float ggxD(float n_dot_h, float alpha);
float smithLambda(float n_dot_x, float alpha);
// Height-correlated visibility V = G2 / (4 n.v n.l), in a form finite at grazing angles.
float ggxVisibility(float n_dot_v, float n_dot_l, float alpha);
// G1(v) / (n.v), finite as n.v -> 0.
float ggxG1OverCos(float n_dot_v, float alpha);
glm::vec3 fresnelSchlick(const glm::vec3& f0, float cos_theta);
// Heitz 2018 visible-normal sample; v local with v.z > 0. Returns the half vector.
glm::vec3 sampleGgxVndf(const glm::vec3& v, float alpha, float u0, float u1);
// Half vector drawn from D(h) (n.h) (the prefilter's lobe, Karis 2013).
glm::vec3 sampleGgxNdf(float alpha, float u0, float u1);

struct BsdfSample {
  glm::vec3 l{0.0f};       // local
  glm::vec3 weight{0.0f};  // f cos / pdf, or the delta lobe's weight
  float pdf = 0.0f;        // combined pdf of the non-delta lobes; 0 for a delta sample
  bool delta = false;
  bool valid = false;
};

// Probability of picking the specular lobe; 1 for pure metals.
float specularProbability(const Material& m, float n_dot_v);
// f(v, l) without any delta component (local v, l; v.z > 0).
glm::vec3 evalBsdf(const Material& m, const glm::vec3& v, const glm::vec3& l);
// Pdf of sampleBsdf producing l, excluding delta lobes.
float pdfBsdf(const Material& m, const glm::vec3& v, const glm::vec3& l);
BsdfSample sampleBsdf(const Material& m, const glm::vec3& v, float u0, float u1, float u_lobe);
// True when the material has a non-delta component (so next-event estimation applies).
inline bool hasSmoothLobe(const Material& m) {
  return shared::bsdfHasSmoothLobe({m.base_color, m.f0, m.metallic, m.alpha});
}

}  // namespace rdm
