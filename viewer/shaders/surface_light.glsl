// Light leaving a voxel surface towards v (docs/spec.md section 6): indirect diffuse from the
// face light or the level-7 RDMs (or the flat ambient), indirect specular `lr` supplied by the caller, the
// shadow-mapped sun and emission, each switched by its term.
#ifndef VIEWER_SURFACE_LIGHT_GLSL
#define VIEWER_SURFACE_LIGHT_GLSL

#include "face_light.glsl"
#include "shading.glsl"
#include "sun_shadow.glsl"

// The weight of the indirect specular radiance in the light leaving the surface (split sum),
// from the surface's dfgLookup (A, B, C).
vec3 specularWeight(SurfaceMaterial s, vec3 abc) { return s.f0 * abc.x + abc.y; }

// slot, face: the RDM face the surface belongs to; p01: the point in that slot (0..1 per
// axis); p: the point in world units; n: the surface normal.
vec3 surfaceRadiance(SurfaceMaterial s, ivec3 slot, int face, vec3 p01, vec3 p, vec3 n, vec3 v,
                     vec3 lr) {
  float n_dot_v = max(dot(n, v), 1e-4);
  vec3 abc = dfgLookup(s.level, n_dot_v);
  vec3 color = vec3(0.0);
  if (termOn(kTermDiffuse)) {
    vec3 l7 = termOn(kTermRdm) ? diffuseRadiance(slot, face, p01) : frame.ambient.rgb;
    color += (1.0 - s.metallic) * (vec3(1.0) - s.f0) * abc.z * s.color * l7;
  }
  if (termOn(kTermSpecular)) color += lr * specularWeight(s, abc);
  if (termOn(kTermSun) && frame.sun_direction.w > 0.0) {
    vec3 l = frame.sun_direction.xyz;
    float vis = (termOn(kTermShadows) && dot(n, l) > 0.0) ? sunVisibility(p, n) : 1.0;
    color += sunBsdfCos(s, n, v, l) * frame.sun_irradiance.rgb * vis;
  }
  if (termOn(kTermEmission)) color += s.emission;
  return color;
}

#endif  // VIEWER_SURFACE_LIGHT_GLSL
