// The BSDF's math is defined once, in shaders/shared/rdm_shared.h, which the Vulkan kernel
// and the viewer's shaders compile too; these functions adapt the core's types to it.
#include "rdm/trace/bsdf.h"

#include <algorithm>
#include <cmath>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

shared::BsdfMaterial bsdfMaterial(const Material& m) {
  return {m.base_color, m.f0, m.metallic, m.alpha};
}

}  // namespace

float ggxD(float n_dot_h, float alpha) {
  return shared::bsdfGgxD(n_dot_h, alpha);
}

float smithLambda(float n_dot_x, float alpha) {
  float c2 = n_dot_x * n_dot_x;
  float s2 = std::max(0.0f, 1.0f - c2);
  return 0.5f * (-1.0f + std::sqrt(1.0f + alpha * alpha * s2 / std::max(c2, 1e-30f)));
}

float ggxVisibility(float n_dot_v, float n_dot_l, float alpha) {
  return shared::bsdfVisibility(n_dot_v, n_dot_l, alpha);
}

float ggxG1OverCos(float n_dot_v, float alpha) {
  return shared::bsdfG1OverCos(n_dot_v, alpha);
}

glm::vec3 fresnelSchlick(const glm::vec3& f0, float cos_theta) {
  return shared::bsdfFresnel(f0, cos_theta);
}

glm::vec3 sampleGgxVndf(const glm::vec3& v, float alpha, float u0, float u1) {
  return shared::bsdfSampleVndf(v, alpha, u0, u1);
}

glm::vec3 sampleGgxNdf(float alpha, float u0, float u1) {
  return shared::bsdfSampleNdf(alpha, u0, u1);
}

float specularProbability(const Material& m, float n_dot_v) {
  return shared::bsdfSpecularProbability(bsdfMaterial(m), n_dot_v);
}

glm::vec3 evalBsdf(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  return shared::bsdfEval(bsdfMaterial(m), v, l);
}

float pdfBsdf(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  return shared::bsdfPdf(bsdfMaterial(m), v, l);
}

BsdfSample sampleBsdf(const Material& m, const glm::vec3& v, float u0, float u1, float u_lobe) {
  const shared::BsdfDraw d = shared::bsdfSample(bsdfMaterial(m), v, u0, u1, u_lobe);
  BsdfSample s;
  s.l = d.l, s.weight = d.weight, s.pdf = d.pdf, s.delta = d.delta, s.valid = d.valid;
  return s;
}

}  // namespace rdm
