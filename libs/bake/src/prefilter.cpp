#include "rdm/bake/prefilter.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

#include "rdm/base/check.h"
#include "rdm/trace/bsdf.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sampling.h"
#include "rdm/transport/sobol.h"

namespace rdm {
namespace {

// Points per output texel of a rough level's kernel; tap weights below kPruneWeight of the
// texel's total are dropped (and the rest renormalised): docs/spec.md section 3.1.
constexpr uint32_t kKernelPoints = 128;
constexpr float kPruneWeight = 1e-6f;

int mipCount(int size) {
  int n = 1;
  while ((size >> (n - 1)) > 1) ++n;
  return n;
}

void addBilinear(int size, int mip, glm::vec2 uv, float weight, std::vector<KernelTap>& taps) {
  const int s = size >> mip;
  const uint32_t base = mipOffset(size, mip);
  float x = (uv.x + 1.0f) * 0.5f * float(s) - 0.5f;
  float y = (uv.y + 1.0f) * 0.5f * float(s) - 0.5f;
  x = std::clamp(x, 0.0f, float(s - 1)), y = std::clamp(y, 0.0f, float(s - 1));
  const int x0 = std::min(int(x), s - 1), y0 = std::min(int(y), s - 1);
  const int x1 = std::min(x0 + 1, s - 1), y1 = std::min(y0 + 1, s - 1);
  const float fx = x - float(x0), fy = y - float(y0);
  auto tap = [&](int i, int j, float w) {
    if (w > 0.0f) taps.push_back({base + uint32_t(j * s + i), weight * w});
  };
  tap(x0, y0, (1 - fx) * (1 - fy)), tap(x1, y0, fx * (1 - fy));
  tap(x0, y1, (1 - fx) * fy), tap(x1, y1, fx * fy);
}

// Merges equal texels, prunes negligible weights and normalises to a sum of 1.
void finishTexel(std::vector<KernelTap>& taps, PrefilterKernel& k) {
  std::sort(taps.begin(), taps.end(),
            [](const KernelTap& a, const KernelTap& b) { return a.texel < b.texel; });
  std::vector<KernelTap> merged;
  double total = 0.0;
  for (const KernelTap& t : taps) {
    total += t.weight;
    if (!merged.empty() && merged.back().texel == t.texel) {
      merged.back().weight += t.weight;
    } else {
      merged.push_back(t);
    }
  }
  double kept = 0.0;
  size_t first = k.taps.size();
  for (const KernelTap& t : merged) {
    if (t.weight >= kPruneWeight * total) k.taps.push_back(t), kept += t.weight;
  }
  for (size_t i = first; i < k.taps.size(); ++i) k.taps[i].weight = float(k.taps[i].weight / kept);
  k.begin.push_back(uint32_t(k.taps.size()));
  taps.clear();
}

// The hemi-oct grid's eight symmetries (the dihedral group of the local (x, y) square) act on
// texel indices at every mip alike: kFlipY (i, j) -> (j, i) negates y, kFlipX
// (i, j) -> (S-1-j, S-1-i) negates x, kSwap (i, j) -> (i, S-1-j) exchanges x and y.
enum : int { kFlipY = 1, kFlipX = 2, kSwap = 4 };

glm::ivec2 applySymmetry(int g, glm::ivec2 t, int s) {
  if (g & kSwap) t = {t.x, s - 1 - t.y};
  if (g & kFlipX) t = {s - 1 - t.y, s - 1 - t.x};
  if (g & kFlipY) t = {t.y, t.x};
  return t;
}

// The symmetry g with texel = g(canonical), canonical's central direction having x >= y >= 0.
int canonicalOf(int i, int j, int s, glm::ivec2& canonical) {
  const glm::ivec3 d = shared::texelCentralDirection(i, j, s);
  int g = 0;
  glm::ivec2 t(i, j);
  int x = d.x, y = d.y;
  if (y < 0) t = applySymmetry(kFlipY, t, s), y = -y, g |= kFlipY;
  if (x < 0) t = applySymmetry(kFlipX, t, s), x = -x, g |= kFlipX;
  if (y > x) t = applySymmetry(kSwap, t, s), g |= kSwap;
  canonical = t;
  return g;
}

// Inverse order of canonicalOf's steps: texel = flipY(flipX(swap(canonical))).
glm::ivec2 fromCanonical(int g, glm::ivec2 t, int s) {
  if (g & kSwap) t = applySymmetry(kSwap, t, s);
  if (g & kFlipX) t = applySymmetry(kFlipX, t, s);
  if (g & kFlipY) t = applySymmetry(kFlipY, t, s);
  return t;
}

uint32_t mapTap(int g, uint32_t texel, int base_size) {
  int mip = 0;
  while (texel >= mipOffset(base_size, mip + 1)) ++mip;
  const int s = base_size >> mip;
  const uint32_t local = texel - mipOffset(base_size, mip);
  const glm::ivec2 t =
      fromCanonical(g, glm::ivec2(int(local % uint32_t(s)), int(local / uint32_t(s))), s);
  return mipOffset(base_size, mip) + uint32_t(t.y * s + t.x);
}

// GGX prefiltered importance sampling (Karis 2013; cmgen): Hammersley half vectors around the
// texel's central direction w, reflected, weighted by w.l, each looked up at the mip whose texel
// solid angle matches the point's share 1 / (N pdf) (Colbert and Krivanek 2007), trilinearly.
void buildGgxTexel(int level, int size, int base_size, int i, int j, std::vector<KernelTap>& taps) {
  const float alpha = shared::roughnessAlpha(level);
  const float texel_solid_angle = 2.0f * kPi / float(base_size * base_size);
  const float max_lod = float(mipCount(base_size) - 1);
  const glm::vec3 w = glm::normalize(glm::vec3(shared::texelCentralDirection(i, j, size)));
  const Frame frame = frameAround(w);
  for (uint32_t p = 0; p < kKernelPoints; ++p) {
    const float u0 = (float(p) + 0.5f) / float(kKernelPoints), u1 = radicalInverse2(p);
    const glm::vec3 h = frame.toWorld(sampleGgxNdf(alpha, u0, u1));
    const float wh = glm::dot(w, h);
    const glm::vec3 l = 2.0f * wh * h - w;
    const float wl = glm::dot(w, l);
    if (l.z <= 0.0f || wl <= 0.0f) continue;
    const float pdf = ggxD(wh, alpha) * 0.25f;
    float lod = 0.0f;
    if (pdf > 0.0f && std::isfinite(pdf)) {
      lod = 0.5f * std::log2(1.0f / (float(kKernelPoints) * pdf * texel_solid_angle));
    }
    lod = std::clamp(lod, 0.0f, max_lod);
    const int m0 = std::min(int(lod), int(max_lod));
    const float f = lod - float(m0);
    const glm::vec2 uv = shared::hemiOctEncode(glm::normalize(l));
    addBilinear(base_size, m0, uv, wl * (1.0f - f), taps);
    if (f > 0.0f) addBilinear(base_size, std::min(m0 + 1, int(max_lod)), uv, wl * f, taps);
  }
}

// Texels of one symmetry class share one quadrature, mapped by the symmetry (which is
// orthogonal, so it carries the GGX lobe around w onto the lobe around g(w)).
void buildGgx(int level, int size, int base_size, PrefilterKernel& k) {
  std::map<int, PrefilterKernel> canonical;  // by canonical texel index
  std::vector<KernelTap> taps;
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      glm::ivec2 c;
      const int g = canonicalOf(i, j, size, c);
      PrefilterKernel& ck = canonical[c.y * size + c.x];
      if (ck.begin.empty()) {
        ck.begin.push_back(0);
        buildGgxTexel(level, size, base_size, c.x, c.y, taps);
        finishTexel(taps, ck);
      }
      for (const KernelTap& t : ck.taps) taps.push_back({mapTap(g, t.texel, base_size), t.weight});
      std::sort(taps.begin(), taps.end(),
                [](const KernelTap& a, const KernelTap& b) { return a.texel < b.texel; });
      k.taps.insert(k.taps.end(), taps.begin(), taps.end());
      k.begin.push_back(uint32_t(k.taps.size()));
      taps.clear();
    }
}

}  // namespace

RadianceMap::RadianceMap(int size) : size_(size) {
  RDM_CHECK(size >= 1 && (size & (size - 1)) == 0);
  texels_ = mipOffset(size, mipCount(size));
  mean_.assign(texels_ + 1, glm::vec3(0.0f));
  variance_.assign(texels_ + 1, glm::vec3(0.0f));
}

void RadianceMap::set(int i, int j, const glm::vec3& mean, const glm::vec3& variance) {
  mean_[size_t(j) * size_ + i] = mean;
  variance_[size_t(j) * size_ + i] = variance;
}

void RadianceMap::estimateVarianceFromBlocks() {
  if (size_ < 2) return;
  for (int j = 0; j < size_; j += 2)
    for (int i = 0; i < size_; i += 2) {
      glm::vec3 sum(0.0f), sum2(0.0f);
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
          const glm::vec3 m = mean(i + a, j + b);
          sum += m, sum2 += m * m;
        }
      const glm::vec3 var = glm::max((sum2 - 0.25f * sum * sum) / 3.0f, glm::vec3(0.0f));
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) variance_[size_t(j + b) * size_ + size_t(i + a)] = var;
    }
}

void RadianceMap::buildMips() {
  for (int m = 1; m < mipCount(size_); ++m) {
    const int s = size_ >> m;
    const uint32_t dst = mipOffset(size_, m), src = mipOffset(size_, m - 1);
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i) {
        glm::vec3 sum(0.0f), var(0.0f);
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a) {
            const size_t c = src + size_t(2 * j + b) * size_t(2 * s) + size_t(2 * i + a);
            sum += mean_[c], var += variance_[c];
          }
        mean_[dst + size_t(j) * s + i] = 0.25f * sum;
        variance_[dst + size_t(j) * s + i] = 0.0625f * var;
      }
  }
}

uint32_t mipOffset(int size, int mip) {
  uint32_t offset = 0;
  for (int m = 0; m < mip; ++m) offset += uint32_t(size >> m) * uint32_t(size >> m);
  return offset;
}

const PrefilterKernel& prefilterKernel(int level, int size, int base_size) {
  RDM_CHECK(level >= 1 && level < shared::kDiffuseLevel && size <= base_size);
  using Key = std::tuple<int, int, int>;
  struct Entry {
    std::once_flag once;
    PrefilterKernel kernel;
  };
  static std::mutex mutex;
  static std::map<Key, std::unique_ptr<Entry>> cache;
  Entry* entry;
  {
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<Entry>& e = cache[Key(level, size, base_size)];
    if (!e) e = std::make_unique<Entry>();
    entry = e.get();
  }
  std::call_once(entry->once, [&] {
    entry->kernel.begin.push_back(0);
    buildGgx(level, size, base_size, entry->kernel);
  });
  return entry->kernel;
}

void applyKernel(const PrefilterKernel& kernel, const RadianceMap& map, int texel, glm::vec3& mean,
                 glm::vec3& variance) {
  // A texel's R, G, B in lanes 0..2 of one 4-float load (lane 3 is the next texel's R, or
  // the map's padding, and is dropped): per lane the same products and sums, in the taps'
  // order, as glm's vec3 (no FMA: -ffp-contract=off), so the same bits. Highway's static
  // target on the x86-64 baseline is its scalar emulation; GCC's vectors give SSE2 (NEON on
  // Arm). The sums stay in registers: summed through `mean` and `variance`, which may alias
  // the map, each tap's sums went to memory and back (docs/performance.md, "Prefilter and
  // writing against memcpy").
  using Float4 = float __attribute__((vector_size(16)));
  Float4 m_sum = {0.0f, 0.0f, 0.0f, 0.0f}, v_sum = m_sum;
  const float* m = &map.means()[0].x;
  const float* v = &map.variances()[0].x;
  const KernelTap* tap = kernel.taps.data() + kernel.begin[size_t(texel)];
  const KernelTap* end = kernel.taps.data() + kernel.begin[size_t(texel) + 1];
  for (; tap != end; ++tap) {
    Float4 m_texel, v_texel;
    std::memcpy(&m_texel, m + 3 * size_t(tap->texel), sizeof(Float4));
    std::memcpy(&v_texel, v + 3 * size_t(tap->texel), sizeof(Float4));
    const float w = tap->weight, w2 = w * w;
    m_sum += w * m_texel;
    v_sum += w2 * v_texel;
  }
  mean = glm::vec3(m_sum[0], m_sum[1], m_sum[2]);
  variance = glm::vec3(v_sum[0], v_sum[1], v_sum[2]);
}

}  // namespace rdm
