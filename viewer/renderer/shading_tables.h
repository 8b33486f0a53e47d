// Start-up CPU tables for the real-time shading of docs/spec.md section 6:
//  - the split-sum DFG table (Karis 2013) built with the the spec's BSDF: GGX D, the
//    height-correlated Smith G2 (rdm::ggxVisibility) and Schlick F with F90 = 1, so that
//    specular = L_prefiltered (F0 A + B);
//  - the directional albedo factor C(mu) of the diffuse lobe (1 - F(v.h)) c / pi, so that
//    with uniform incident radiance L the diffuse reflection is (1 - m)(1 - F0) C(n.v) c L.
// Rows are the eight roughness levels (materials only have those); columns sample
// mu = n.v at (c + 0.5) / kDfgColumns; the shader interpolates linearly in mu and clamps.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace rdm::viewer {

inline constexpr int kDfgColumns = 64;
inline constexpr int kDfgRows = 8;

struct ShadingTables {
  // kDfgRows x kDfgColumns entries (A, B, C, 0), row-major by level.
  std::vector<glm::vec4> dfg;
  glm::vec4 at(int level, int column) const { return dfg[size_t(level) * kDfgColumns + column]; }
  // Linear interpolation in mu, as the shader does.
  glm::vec4 lookup(int level, float mu) const;
};

// Deterministic quadrature (Hammersley points) with `samples` per entry.
ShadingTables computeShadingTables(int samples = 1024);

// One entry: (A, B) for GGX alpha at mu = n.v (alpha = 0 is the mirror), and C(mu).
glm::vec2 integrateDfg(float alpha, float mu, int samples);
float integrateDiffuseAlbedo(float mu, int samples);

}  // namespace rdm::viewer
