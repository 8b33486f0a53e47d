#include "rdm/scene/lights.h"
#include "rdm/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rdm {

float luminance(const glm::vec3& c) {
  return shared::lumaRec709(c);
}

SunLight makeSunLight(const glm::dvec3& direction, const glm::dvec3& irradiance,
                      double angular_radius_deg) {
  SunLight sun;
  sun.present = true;
  double theta = angular_radius_deg * std::numbers::pi / 180.0;
  double half_sin = std::sin(theta / 2.0);
  double omega = 4.0 * std::numbers::pi * half_sin * half_sin;
  sun.direction = glm::vec3(normalizeDirection(direction));
  sun.irradiance = glm::vec3(irradiance);
  sun.radiance = glm::vec3(irradiance / omega);
  sun.one_minus_cos_max = float(2.0 * half_sin * half_sin);
  sun.disc_c2 = float(4.0 * half_sin * half_sin);
  sun.pdf = float(1.0 / omega);
  return sun;
}

int EmitterList::pick(float u) const {
  auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
  int index = int(it - cdf.begin());
  return std::min(index, int(cdf.size()) - 1);
}

}  // namespace rdm
