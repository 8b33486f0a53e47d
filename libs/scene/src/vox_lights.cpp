#include "vox_lights.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace rdm::vox {
namespace {

// Irradiance of MagicaVoxel's sun per unit of `_i`: its default 0.6 gives the import's
// default sun (about 3).
constexpr double kSunPerIntensity = 5.0;

// Up to `count` numbers of an attribute; how many parsed (finite).
int numbers(const Dict& d, const char* key, int count, double* out) {
  auto it = d.find(key);
  if (it == d.end()) return 0;
  std::istringstream in(it->second);
  int n = 0;
  while (n < count && in >> out[n] && std::isfinite(out[n])) ++n;
  return n;
}

// `_k` or `_color` ("r g b", 0..255) as linear-ish 0..1 factors; white when absent.
glm::dvec3 colour(const Dict& d) {
  double c[3] = {255, 255, 255};
  if (numbers(d, "_k", 3, c) != 3 && numbers(d, "_color", 3, c) != 3) c[0] = c[1] = c[2] = 255;
  return glm::clamp(glm::dvec3(c[0], c[1], c[2]) / 255.0, 0.0, 1.0);
}

double intensity(const Dict& d, double fallback) {
  double i = fallback;
  return numbers(d, "_i", 1, &i) == 1 ? std::clamp(i, 0.0, 100.0) : fallback;
}

std::string format(const char* fmt, double a, double b = 0, double c = 0, double e = 0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, e);
  return buf;
}

const Dict* find(const VoxFile& f, const std::string& type, const std::string& chunk) {
  for (const Dict& d : f.render_objects) {
    auto t = d.find("_type");
    if ((t != d.end() && t->second == type) || d.at("_chunk") == chunk) return &d;
  }
  return nullptr;
}

// Sun from `_angle` "elevation azimuth" (degrees; azimuth from MagicaVoxel's front, -Y,
// towards +X: an assumed convention), `_i` x `_k`, and `_area` as the angular diameter in
// units of 90 degrees (assumed), clamped to the scene's 0.01..10 degree radius.
void mapSun(const Dict& d, Scene& scene, std::vector<std::string>& mapped) {
  double angle[2] = {50, 50}, area = 0.0;
  numbers(d, "_angle", 2, angle);
  const double e = glm::radians(std::clamp(angle[0], 1.0, 90.0)), a = glm::radians(angle[1]);
  Sun sun = *scene.sun;
  sun.direction = {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)};
  sun.irradiance = kSunPerIntensity * intensity(d, 0.6) * colour(d);
  if (numbers(d, "_area", 1, &area) == 1)
    sun.angular_radius_deg = std::clamp(area * 45.0, 0.27, 10.0);
  scene.sun = sun;
  const std::string source = d.at("_chunk") == "rLIT" ? "rLIT" : "rOBJ _inf";
  mapped.push_back("sun: from " + source +
                   format(": elevation %.0f, azimuth %.0f degrees (convention assumed), "
                          "irradiance %.2f (_i x 5), angular radius %.2f degrees",
                          angle[0], angle[1], sun.irradiance.g, sun.angular_radius_deg));
}

void mapSky(const Dict& d, Scene& scene, std::vector<std::string>& mapped) {
  const glm::dvec3 sky = intensity(d, 0.7) * colour(d);
  scene.sky.zenith = scene.sky.horizon = sky;
  scene.ambient = sky;
  mapped.push_back(
      format("sky: from the uniform sky (_i x _k): zenith and horizon %.2f %.2f %.2f; "
             "ground kept",
             sky.r, sky.g, sky.b));
}

}  // namespace

void mapLights(const VoxFile& f, Scene& scene, std::vector<std::string>& mapped,
               std::vector<std::string>& dropped) {
  scene.sky = Sky{{0.3, 0.5, 0.9}, {0.8, 0.85, 0.9}, {0.2, 0.18, 0.15}};
  scene.sun = Sun{{0.3, 1.0, 0.2}, {3.0, 2.9, 2.7}, 0.27};
  scene.ambient = {0.3, 0.32, 0.36};
  const Dict* sun = find(f, "_inf", "rLIT");
  const Dict* sky = find(f, "_uni", "rAIR");
  if (sun) mapSun(*sun, scene, mapped);
  if (sky) mapSky(*sky, scene, mapped);
  if (!sun) mapped.push_back("sun: the import's default (no rOBJ _inf or rLIT in the file)");
  if (!sky) mapped.push_back("sky: the import's default (no uniform sky in the file)");
  std::string other;
  for (const Dict& d : f.render_objects) {
    auto t = d.find("_type");
    if (t == d.end() || t->second == "_inf" || t->second == "_uni") continue;
    other += (other.empty() ? "" : ", ") + t->second;
  }
  if (!other.empty())
    dropped.push_back("render settings " + other + ": MagicaVoxel's renderer only");
}

}  // namespace rdm::vox
