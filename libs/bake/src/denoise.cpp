#include "rdm/bake/denoise.h"

#include <algorithm>
#include <cmath>

#include "rdm/base/check.h"
#include "rdm/scene/lights.h"

namespace rdm {

namespace {

using shared::DenoiseTexel;

// The 3 x 3 mean of the squared standard errors around texel (i, j) of a face at (x0, y0).
glm::vec3 guideVariance(const RdmData& rdm, int x0, int y0, int size, int i, int j) {
  glm::dvec3 sum(0.0);
  int n = 0;
  for (int y = std::max(0, j - 1); y <= std::min(size - 1, j + 1); ++y) {
    for (int x = std::max(0, i - 1); x <= std::min(size - 1, i + 1); ++x, ++n) {
      const float* e =
          &rdm.stderr_rgb[(size_t(y0 + y) * size_t(rdm.image.width) + size_t(x0 + x)) * 3];
      for (int k = 0; k < 3; ++k) sum[k] += double(e[k]) * double(e[k]);
    }
  }
  return glm::vec3(sum / double(n));
}

// Face f of `center` filtered into `out`: every texel the floor admits takes the window of
// each face of `faces` (its own first), the others' shifted by their parallax.
void denoiseFace(const RdmData& center, int f, const std::vector<const RdmData*>& set,
                 const DenoiseSettings& s, RdmData& out, DenoiseStats& stats) {
  const int size = center.id.size, window = denoiseWindow(center, s);
  const shared::DenoiseParams params = denoiseParams(s);
  std::vector<std::vector<DenoiseTexel>> faces;
  for (const RdmData* rdm : set) faces.push_back(denoiseFaceTexels(*rdm, f));
  const auto at = [size](const std::vector<DenoiseTexel>& face, int x,
                         int y) -> const DenoiseTexel& {
    return face[size_t(y) * size_t(size) + size_t(x)];
  };
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      const DenoiseTexel& c = at(faces[0], i, j);
      if (!shared::denoiseNeeded(c, params.min_relative_error)) {
        storeDenoisedTexel(out, f, i, j, c, c, false, stats);
        continue;
      }
      const int x0 = std::max(0, i - s.radius), x1 = std::min(size - 1, i + s.radius);
      const int y0 = std::max(0, j - s.radius), y1 = std::min(size - 1, j + s.radius);
      float nearest = c.rgbz.w;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          nearest = shared::denoiseNearer(nearest, at(faces[0], x, y).rgbz.w);
      const float parallax = shared::denoiseParallax(size, nearest);
      shared::DenoiseSums sums{0.0f, glm::vec3(0.0f), glm::vec3(0.0f)};
      for (size_t k = 0; k < faces.size(); ++k) {
        const float shift = k == 0 ? 0.0f : parallax * parallax;
        for (int y = std::max(0, j - window); y <= std::min(size - 1, j + window); ++y) {
          for (int x = std::max(0, i - window); x <= std::min(size - 1, i + window); ++x) {
            const float d2 = float((x - i) * (x - i) + (y - j) * (y - j)) + shift;
            shared::denoiseAddTap(sums, c, at(faces[k], x, y), d2, params);
          }
        }
      }
      storeDenoisedTexel(out, f, i, j, c, shared::denoiseResult(sums, c), true, stats);
    }
  }
}

}  // namespace

bool hasStandardError(const RdmData& rdm) {
  return rdm.stderr_rgb.size() * 4 == rdm.image.pixels.size() * 3;
}

std::vector<DenoiseTexel> denoiseFaceTexels(const RdmData& rdm, int f) {
  RDM_CHECK(hasStandardError(rdm));
  const int size = rdm.id.size, x0 = size * (f % 2), y0 = size * (f / 2);
  std::vector<DenoiseTexel> out(size_t(size) * size_t(size));
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      const size_t p = size_t(y0 + j) * size_t(rdm.image.width) + size_t(x0 + i);
      const float* v = &rdm.image.pixels[p * 4];
      const float* e = &rdm.stderr_rgb[p * 3];
      out[size_t(j) * size_t(size) + size_t(i)] = {
          glm::vec4(v[0], v[1], v[2], v[3]), glm::vec4(e[0], e[1], e[2], 0.0f),
          glm::vec4(guideVariance(rdm, x0, y0, size, i, j), 0.0f)};
    }
  }
  return out;
}

std::vector<const RdmData*> denoiseFaceSet(const RdmData& center, int f,
                                           const PlaneNeighbours& plane,
                                           const DenoiseSettings& settings) {
  std::vector<const RdmData*> set{&center};
  if (!settings.across_slots) return set;
  for (const RdmData* n : plane) {
    if (n && !n->skipped[size_t(f)] && n->id.size == center.id.size && hasStandardError(*n))
      set.push_back(n);
  }
  return set;
}

int denoiseWindow(const RdmData& center, const DenoiseSettings& settings) {
  const bool derived = settings.prefiltered && center.id.level > 0;
  return derived && !settings.derived_window ? 0 : settings.radius;
}

shared::DenoiseParams denoiseParams(const DenoiseSettings& s) {
  return {1.0f / (2.0f * s.spatial_sigma * s.spatial_sigma),
          1.0f / (2.0f * s.color_sigma * s.color_sigma), s.depth_sigma, s.min_relative_error};
}

void storeDenoisedTexel(RdmData& out, int f, int i, int j, const DenoiseTexel& read,
                        const DenoiseTexel& result, bool filtered, DenoiseStats& stats) {
  const int size = out.id.size;
  const size_t p =
      size_t(size * (f / 2) + j) * size_t(out.image.width) + size_t(size * (f % 2) + i);
  for (int k = 0; k < 3; ++k) {
    out.image.pixels[p * 4 + size_t(k)] = result.rgbz[k];
    out.stderr_rgb[p * 3 + size_t(k)] = result.error[k];
  }
  ++stats.texels;
  stats.filtered += filtered ? 1 : 0;
  stats.value_before += luminance(glm::vec3(read.rgbz));
  stats.error_before += luminance(glm::vec3(read.error));
  stats.value_after += luminance(glm::vec3(result.rgbz));
  stats.error_after += luminance(glm::vec3(result.error));
}

void DenoiseStats::add(const DenoiseStats& part) {
  rdms += part.rdms;
  texels += part.texels;
  filtered += part.filtered;
  value_before += part.value_before;
  error_before += part.error_before;
  value_after += part.value_after;
  error_after += part.error_after;
}

nlohmann::json denoiseReportJson(const DenoiseSettings& settings, const DenoiseStats& stats) {
  return {{"scope", settings.across_slots ? "blocks" : "tile"},
          {"radius", settings.radius},
          {"rdms", stats.rdms},
          {"texels", stats.texels},
          {"texels_filtered", stats.filtered},
          {"seconds", stats.seconds},
          {"cpu_seconds", stats.cpu_seconds},
          {"relative_error_before", stats.relativeErrorBefore()},
          {"relative_error_after", stats.relativeErrorAfter()}};
}

std::array<glm::ivec3, 4> planeNeighbourSlots(const glm::ivec3& slot, int axis) {
  RDM_CHECK(axis >= 0 && axis < 3);
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
  glm::ivec3 e1(0), e2(0);
  e1[a1] = 1;
  e2[a2] = 1;
  return {slot - e1, slot + e1, slot - e2, slot + e2};
}

RdmData denoiseRdm(const RdmData& center, const std::array<PlaneNeighbours, 3>& neighbours,
                   const DenoiseSettings& settings, DenoiseStats& stats) {
  RdmData out = center;
  ++stats.rdms;
  // Without its standard error (an RDM copied from a store) an RDM has no guide: kept.
  if (!hasStandardError(center)) return out;
  for (int f = 0; f < 6; ++f) {
    if (center.skipped[size_t(f)]) continue;
    denoiseFace(center, f, denoiseFaceSet(center, f, neighbours[size_t(f / 2)], settings), settings,
                out, stats);
  }
  return out;
}

}  // namespace rdm
