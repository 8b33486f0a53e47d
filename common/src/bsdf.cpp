#include "rdm/bsdf.h"

#include <algorithm>
#include <cmath>

#include "rdm/sampling.h"

namespace rdm {
namespace {

bool finite3(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::vec3 diffuseTerm(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  glm::vec3 h = glm::normalize(v + l);
  glm::vec3 f = fresnelSchlick(m.f0, std::clamp(glm::dot(v, h), 0.0f, 1.0f));
  return (1.0f - m.metallic) * (glm::vec3(1.0f) - f) * m.base_color / kPi;
}

glm::vec3 specularTerm(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  glm::vec3 h = glm::normalize(v + l);
  float d = ggxD(h.z, m.alpha);
  glm::vec3 f = fresnelSchlick(m.f0, std::clamp(glm::dot(v, h), 0.0f, 1.0f));
  return d * ggxVisibility(v.z, l.z, m.alpha) * f;
}

float specularPdf(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  glm::vec3 h = glm::normalize(v + l);
  if (h.z <= 0.0f) return 0.0f;
  return ggxD(h.z, m.alpha) * ggxG1OverCos(v.z, m.alpha) * 0.25f;
}

}  // namespace

float ggxD(float n_dot_h, float alpha) {
  // c2 (a2 - 1) + 1 written as s2 + c2 a2: no cancellation when alpha is tiny.
  float a2 = alpha * alpha;
  float c2 = n_dot_h * n_dot_h;
  float denom = std::max(0.0f, 1.0f - c2) + c2 * a2;
  denom = std::max(denom, 1e-15f);
  return a2 / (kPi * denom * denom);
}

float smithLambda(float n_dot_x, float alpha) {
  float c2 = n_dot_x * n_dot_x;
  float s2 = std::max(0.0f, 1.0f - c2);
  return 0.5f * (-1.0f + std::sqrt(1.0f + alpha * alpha * s2 / std::max(c2, 1e-30f)));
}

float ggxVisibility(float n_dot_v, float n_dot_l, float alpha) {
  float a2 = alpha * alpha;
  float gv = n_dot_l * std::sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2);
  float gl = n_dot_v * std::sqrt(n_dot_l * n_dot_l * (1.0f - a2) + a2);
  float denom = gv + gl;
  return denom > 0.0f ? 0.5f / denom : 0.0f;
}

float ggxG1OverCos(float n_dot_v, float alpha) {
  float a2 = alpha * alpha;
  return 2.0f / (n_dot_v + std::sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2));
}

glm::vec3 fresnelSchlick(const glm::vec3& f0, float cos_theta) {
  float x = 1.0f - cos_theta;
  float x2 = x * x;
  return f0 + (glm::vec3(1.0f) - f0) * (x2 * x2 * x);
}

glm::vec3 sampleGgxVndf(const glm::vec3& v, float alpha, float u0, float u1) {
  glm::vec3 vh = glm::normalize(glm::vec3(alpha * v.x, alpha * v.y, v.z));
  float len2 = vh.x * vh.x + vh.y * vh.y;
  glm::vec3 t1 =
      len2 > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(len2) : glm::vec3(1.0f, 0.0f, 0.0f);
  glm::vec3 t2 = glm::cross(vh, t1);
  float r = std::sqrt(u0), phi = 2.0f * kPi * u1;
  float p1 = r * std::cos(phi), p2 = r * std::sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(0.0f, nh.z)));
}

glm::vec3 sampleGgxNdf(float alpha, float u0, float u1) {
  float a2 = alpha * alpha;
  float cos2 = (1.0f - u0) / (1.0f + (a2 - 1.0f) * u0);
  float cos_t = std::sqrt(std::clamp(cos2, 0.0f, 1.0f));
  float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos2));
  float phi = 2.0f * kPi * u1;
  return {sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t};
}

float specularProbability(const Material& m, float n_dot_v) {
  if (m.metallic >= 1.0f) return 1.0f;
  float fs = luminance(fresnelSchlick(m.f0, n_dot_v));
  float fd = (1.0f - m.metallic) * (1.0f - fs) * luminance(m.base_color);
  float p = fs / std::max(fs + fd, 1e-12f);
  return std::clamp(p, 0.05f, 0.95f);
}

glm::vec3 evalBsdf(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  if (v.z <= 0.0f || l.z <= 0.0f) return glm::vec3(0.0f);
  glm::vec3 f = m.metallic < 1.0f ? diffuseTerm(m, v, l) : glm::vec3(0.0f);
  if (m.alpha > 0.0f) f += specularTerm(m, v, l);
  return f;
}

float pdfBsdf(const Material& m, const glm::vec3& v, const glm::vec3& l) {
  if (v.z <= 0.0f || l.z <= 0.0f) return 0.0f;
  float p_spec = specularProbability(m, v.z);
  float pdf = (1.0f - p_spec) * l.z / kPi;
  if (m.alpha > 0.0f) pdf += p_spec * specularPdf(m, v, l);
  return pdf;
}

BsdfSample sampleBsdf(const Material& m, const glm::vec3& v, float u0, float u1, float u_lobe) {
  BsdfSample s;
  if (v.z <= 0.0f) return s;
  float p_spec = specularProbability(m, v.z);
  bool specular = u_lobe < p_spec;
  if (specular && m.alpha == 0.0f) {
    s.l = glm::vec3(-v.x, -v.y, v.z);
    s.weight = fresnelSchlick(m.f0, v.z) / p_spec;
    s.delta = true;
    s.valid = finite3(s.weight);
    return s;
  }
  if (specular) {
    glm::vec3 h = sampleGgxVndf(v, m.alpha, u0, u1);
    s.l = 2.0f * glm::dot(v, h) * h - v;
  } else {
    s.l = sampleCosineHemisphere(u0, u1);
  }
  if (s.l.z <= 0.0f) return s;
  s.pdf = pdfBsdf(m, v, s.l);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = evalBsdf(m, v, s.l) * s.l.z / s.pdf;
  s.valid = finite3(s.weight);
  return s;
}

}  // namespace rdm
