#include "rdm/bake/denoise.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include "rdm/base/check.h"
#include "rdm/base/parallel.h"
#include "rdm/scene/lights.h"

namespace rdm {

namespace {

constexpr float kPi = 3.14159265358979f;
// A texel's hemi-oct square spans a quarter turn in S / 2 texels: pi / S radians per texel.
float parallaxTexels(int size, float depth) {
  return float(size) / (kPi * depth);
}

// One face's texels in an RDM image: face f sits at (S (f % 2), S (f / 2)).
struct FaceTexels {
  const RdmData* rdm = nullptr;
  int x0 = 0, y0 = 0, size = 0;
  // The variance each colour test uses: the 3 x 3 mean of the texels' squared standard errors,
  // since an estimate from a few samples (one sample's, from its 2 x 2 block) is itself noisy.
  std::vector<float> guide_variance;

  FaceTexels(const RdmData* r, int face, int s)
      : rdm(r), x0(s * (face % 2)), y0(s * (face / 2)), size(s) {
    guide_variance.resize(size_t(s) * size_t(s) * 3);
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i)
        meanVariance(i, j, &guide_variance[(size_t(j) * size_t(s) + size_t(i)) * 3]);
  }
  size_t index(int i, int j) const {
    return size_t(y0 + j) * size_t(rdm->image.width) + size_t(x0 + i);
  }
  const float* rgbz(size_t p) const { return &rdm->image.pixels[p * 4]; }
  const float* error(size_t p) const { return &rdm->stderr_rgb[p * 3]; }
  const float* guide(int i, int j) const {
    return &guide_variance[(size_t(j) * size_t(size) + size_t(i)) * 3];
  }

 private:
  void meanVariance(int i, int j, float* out) const {
    double sum[3] = {0.0, 0.0, 0.0};
    int n = 0;
    for (int y = std::max(0, j - 1); y <= std::min(size - 1, j + 1); ++y) {
      for (int x = std::max(0, i - 1); x <= std::min(size - 1, i + 1); ++x, ++n) {
        const float* e = error(index(x, y));
        for (int k = 0; k < 3; ++k) sum[k] += double(e[k]) * double(e[k]);
      }
    }
    for (int k = 0; k < 3; ++k) out[k] = float(sum[k] / n);
  }
};

struct TexelSums {
  double weight = 0.0;
  double rgb[3] = {0.0, 0.0, 0.0};
  double variance[3] = {0.0, 0.0, 0.0};  // sum of w^2 e^2
};

// Adds the window of `face` around (i, j) to `sums`, against the centre's values.
void addWindow(const FaceTexels& face, int size, int i, int j, float extra_distance2,
               const float* c, const float* cv, const DenoiseSettings& s, int radius,
               TexelSums& sums) {
  const float inv_spatial = 1.0f / (2.0f * s.spatial_sigma * s.spatial_sigma);
  const float inv_color = 1.0f / (2.0f * s.color_sigma * s.color_sigma);
  for (int y = std::max(0, j - radius); y <= std::min(size - 1, j + radius); ++y) {
    for (int x = std::max(0, i - radius); x <= std::min(size - 1, i + radius); ++x) {
      const size_t p = face.index(x, y);
      const float* q = face.rgbz(p);
      if (!(q[3] > 0.0f)) continue;  // a dead texel sees nothing
      const float* qe = face.error(p);
      const float* qv = face.guide(x, y);
      const float dz = (q[3] - c[3]) / (s.depth_sigma * std::max(q[3], c[3]));
      float color2 = 0.0f;
      for (int k = 0; k < 3; ++k) {
        const float d = q[k] - c[k];
        const float scale = std::abs(q[k]) + std::abs(c[k]);
        color2 += d * d / (cv[k] + qv[k] + 1e-8f * scale * scale + 1e-30f);
      }
      const float d2 = float((x - i) * (x - i) + (y - j) * (y - j)) + extra_distance2;
      const double w = std::exp(-d2 * inv_spatial - 0.5f * dz * dz - color2 / 3.0f * inv_color);
      sums.weight += w;
      for (int k = 0; k < 3; ++k) {
        sums.rgb[k] += w * q[k];
        sums.variance[k] += w * w * double(qe[k]) * double(qe[k]);
      }
    }
  }
}

// The nearest depth around (i, j): a texel's value mixes the directions around its centre
// (a rough level's lobe), so the nearest surface among them sets its parallax.
float nearestDepth(const FaceTexels& face, int i, int j, int radius) {
  float nearest = face.rgbz(face.index(i, j))[3];
  for (int y = std::max(0, j - radius); y <= std::min(face.size - 1, j + radius); ++y) {
    for (int x = std::max(0, i - radius); x <= std::min(face.size - 1, i + radius); ++x) {
      const float z = face.rgbz(face.index(x, y))[3];
      if (z > 0.0f) nearest = std::min(nearest, z);
    }
  }
  return nearest;
}

// Whether the texel's noise calls for the filter (noise.exr's E against the floor).
bool needsFilter(float value, float error, float depth, float floor) {
  if (!(depth > 0.0f) || error <= 0.0f) return false;
  return value <= 0.0f || error / value >= floor;
}

void denoiseFace(const RdmData& center, int f, const PlaneNeighbours& plane,
                 const DenoiseSettings& s, RdmData& out, DenoiseStats& stats) {
  const int size = center.id.size;
  // A derived level's texels share their noise across its kernel: no window, other blocks only.
  const int window = s.prefiltered && center.id.level > 0 ? 0 : s.radius;
  std::vector<FaceTexels> faces;
  faces.emplace_back(&center, f, size);
  if (s.across_slots) {
    for (const RdmData* n : plane) {
      if (n && !n->skipped[size_t(f)] && n->id.size == size) faces.emplace_back(n, f, size);
    }
  }
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      const size_t p = faces[0].index(i, j);
      const float* c = faces[0].rgbz(p);
      const float* ce = faces[0].error(p);
      ++stats.texels;
      const float value = luminance(glm::vec3(c[0], c[1], c[2]));
      const float error = luminance(glm::vec3(ce[0], ce[1], ce[2]));
      stats.value_before += value, stats.error_before += error;
      if (!needsFilter(value, error, c[3], s.min_relative_error)) {
        stats.value_after += value, stats.error_after += error;
        continue;
      }
      ++stats.filtered;
      const float parallax = parallaxTexels(size, nearestDepth(faces[0], i, j, s.radius));
      TexelSums sums;
      for (size_t k = 0; k < faces.size(); ++k)
        addWindow(faces[k], size, i, j, k == 0 ? 0.0f : parallax * parallax, c,
                  faces[0].guide(i, j), s, window, sums);
      glm::vec3 filtered, filtered_error;
      for (int k = 0; k < 3; ++k) {
        filtered[k] = float(sums.rgb[k] / sums.weight);
        filtered_error[k] = float(std::sqrt(sums.variance[k]) / sums.weight);
        out.image.pixels[p * 4 + size_t(k)] = filtered[k];
        out.stderr_rgb[p * 3 + size_t(k)] = filtered_error[k];
      }
      stats.value_after += luminance(filtered), stats.error_after += luminance(filtered_error);
    }
  }
}

using Key = std::tuple<int, int, int, int>;  // slot and level
Key keyOf(const glm::ivec3& slot, int level) {
  return {slot.x, slot.y, slot.z, level};
}

// Where each RDM is: in `rdms` (first) or in `context`.
struct Locator {
  std::map<Key, std::pair<const RdmSource*, size_t>> where;
  Locator(const RdmSource& rdms, const RdmSource* context) {
    if (context) add(*context);
    add(rdms);  // overrides the context's
  }
  void add(const RdmSource& source) {
    const std::vector<RdmId> ids = source.ids();
    for (size_t i = 0; i < ids.size(); ++i) where[keyOf(ids[i].slot, ids[i].level)] = {&source, i};
  }
};

Status readRdm(const std::pair<const RdmSource*, size_t>& at, RdmData& out) {
  return at.first->visit(at.second, [&](const RdmData& d) { out = d; });
}

// RDM i of `rdms` filtered, its six face neighbours read through `locator`.
Status denoiseOne(const RdmSource& rdms, size_t i, const Locator& locator, const DenoiseSettings& s,
                  RdmData& out, DenoiseStats& stats) {
  RdmData center;
  if (Status st = readRdm({&rdms, i}, center); !st) return st;
  std::map<Key, RdmData> near;
  std::array<PlaneNeighbours, 3> neighbours{};
  for (int axis = 0; axis < 3; ++axis) {
    const std::array<glm::ivec3, 4> slots = planeNeighbourSlots(center.id.slot, axis);
    for (size_t n = 0; n < 4; ++n) {
      const Key key = keyOf(slots[n], center.id.level);
      auto found = locator.where.find(key);
      if (found == locator.where.end()) continue;
      auto [it, fresh] = near.try_emplace(key);
      if (fresh) {
        if (Status st = readRdm(found->second, it->second); !st) return st;
      }
      if (it->second.stderr_rgb.size() * 4 == it->second.image.pixels.size() * 3)
        neighbours[size_t(axis)][n] = &it->second;
    }
  }
  out = denoiseRdm(center, neighbours, s, stats);
  return {};
}

}  // namespace

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
  if (center.stderr_rgb.size() * 4 != center.image.pixels.size() * 3) {
    return out;
  }
  for (int f = 0; f < 6; ++f) {
    if (!center.skipped[size_t(f)])
      denoiseFace(center, f, neighbours[size_t(f / 2)], settings, out, stats);
  }
  return out;
}

Status denoiseRdms(const RdmSource& rdms, const RdmSource* context, RdmSpill& out,
                   const DenoiseSettings& settings, int threads, DenoiseStats& stats) {
  const auto start = std::chrono::steady_clock::now();
  const Locator locator(rdms, context);
  const size_t count = rdms.ids().size();
  const size_t batch = size_t(2 * workerCount(threads));
  std::vector<RdmData> done(batch);
  std::vector<DenoiseStats> part(batch);
  std::vector<Status> failed(batch);
  std::vector<uint64_t> cpu(batch, 0);
  for (size_t first = 0; first < count; first += batch) {
    const size_t n = std::min(batch, count - first);
    parallelFor(n, {threads}, [&](size_t k) {
      const uint64_t cpu0 = threadCpuNanoseconds();
      part[k] = {};
      failed[k] = denoiseOne(rdms, first + k, locator, settings, done[k], part[k]);
      cpu[k] += threadCpuNanoseconds() - cpu0;
      return bool(failed[k]);
    });
    for (size_t k = 0; k < n; ++k) {
      if (!failed[k]) return failed[k];
      out.append(done[k]);
      stats.add(part[k]);
    }
  }
  if (Status s = out.status(); !s) return s;
  for (uint64_t c : cpu) stats.cpu_seconds += double(c) * 1e-9;
  stats.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {};
}

}  // namespace rdm
