// The cross-backend agreement of two bakes of the same RDMs (docs/spec.md section 5), shared by
// the Vulkan tests of both estimators: per texel, per depth and per RDM mean, with the
// failing texels listed.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "rdm/bake/bake.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm::test {

struct Agreement {
  int texels = 0;
  int texel_failures = 0;  // texels outside the per-texel tolerance (radiance)
  int depth_failures = 0;
  int mean_failures = 0;     // RDM channel means outside the per-RDM tolerance
  int rdms_over_budget = 0;  // RDMs with more than 0.1% failing texels
  double max_abs_diff = 0.0;
  std::string listing;  // every failing texel / mean
};

// docs/spec.md section 5: |dZ| <= 1e-4 Z + 1e-5; per texel |dL| <= 4 sqrt(sa^2 + sb^2) + 1e-4 L +
// 1e-6; per RDM |d mean| <= 0.005 mean + 4 sigma_mean + 1e-6; up to 0.1% of an RDM's texels may
// fail.
inline Agreement compareBakes(const BakeResult& a, const BakeResult& b) {
  Agreement g;
  std::ostringstream list;
  EXPECT_EQ(a.rdms.size(), b.rdms.size());
  for (size_t r = 0; r < std::min(a.rdms.size(), b.rdms.size()); ++r) {
    const RdmData& x = a.rdms[r];
    const RdmData& y = b.rdms[r];
    EXPECT_TRUE(x.id == y.id);
    EXPECT_EQ(x.skipped, y.skipped);
    const int S = x.id.size, W = x.image.width, H = x.image.height;
    const bool face_mean = x.id.level == shared::kDiffuseLevel;
    int failures = 0, baked = 0;
    glm::dvec3 mean_a(0.0), mean_b(0.0);
    std::array<glm::dvec3, 6> face_sigma{};  // level 7: one estimate per face
    glm::dvec3 var_sum(0.0);
    for (int py = 0; py < H; ++py)
      for (int px = 0; px < W; ++px) {
        const int face = (py / S) * 2 + px / S;
        if (x.skipped[size_t(face)]) continue;
        ++baked, ++g.texels;
        const size_t p = size_t(py) * W + px;
        const float za = x.image.pixels[p * 4 + 3], zb = y.image.pixels[p * 4 + 3];
        if (!(std::abs(za - zb) <= 1e-4f * std::abs(za) + 1e-5f)) {
          ++g.depth_failures;
          list << "  depth rdm " << r << " (" << px << "," << py << "): " << za << " vs " << zb
               << "\n";
        }
        bool bad = false;
        for (int c = 0; c < 3; ++c) {
          const double la = x.image.pixels[p * 4 + c], lb = y.image.pixels[p * 4 + c];
          const double sa = x.stderr_rgb[p * 3 + c], sb = y.stderr_rgb[p * 3 + c];
          const double tol = 4.0 * std::sqrt(sa * sa + sb * sb) + 1e-4 * std::abs(la) + 1e-6;
          g.max_abs_diff = std::max(g.max_abs_diff, std::abs(la - lb));
          if (!(std::abs(la - lb) <= tol)) bad = true;
          mean_a[c] += la, mean_b[c] += lb;
          if (face_mean) {
            face_sigma[size_t(face)][c] = std::sqrt(sa * sa + sb * sb);
          } else {
            var_sum[c] += sa * sa + sb * sb;
          }
        }
        if (bad) {
          ++failures;
          list << "  texel rdm " << r << " slot (" << x.id.slot.x << "," << x.id.slot.y << ","
               << x.id.slot.z << ") level " << x.id.level << " pixel (" << px << "," << py << "): ("
               << x.image.pixels[p * 4] << "," << x.image.pixels[p * 4 + 1] << ","
               << x.image.pixels[p * 4 + 2] << ") vs (" << y.image.pixels[p * 4] << ","
               << y.image.pixels[p * 4 + 1] << "," << y.image.pixels[p * 4 + 2] << "), sigma "
               << x.stderr_rgb[p * 3] << " / " << y.stderr_rgb[p * 3] << "\n";
        }
      }
    g.texel_failures += failures;
    if (failures > baked / 1000) ++g.rdms_over_budget;
    if (baked == 0) continue;
    for (int c = 0; c < 3; ++c) {
      // Texels of one level-7 face share one estimate: their errors add linearly.
      double var = var_sum[c];
      for (const auto& fs : face_sigma) var += double(S) * S * fs[c] * double(S) * S * fs[c];
      const double sigma_mean = std::sqrt(var) / baked;
      const double ma = mean_a[c] / baked, mb = mean_b[c] / baked;
      if (!(std::abs(ma - mb) <= 0.005 * std::abs(ma) + 4.0 * sigma_mean + 1e-6)) {
        ++g.mean_failures;
        list << "  mean rdm " << r << " channel " << c << ": " << ma << " vs " << mb << " sigma "
             << sigma_mean << "\n";
      }
    }
  }
  g.listing = list.str();
  return g;
}

inline void expectAgreement(const BakeResult& cpu, const BakeResult& vk, const char* what) {
  Agreement g = compareBakes(cpu, vk);
  std::printf(
      "[ %s ] %d texels, %d outside the per-texel tolerance, %d depth, %d means; max |dL| %.3g\n",
      what, g.texels, g.texel_failures, g.depth_failures, g.mean_failures, g.max_abs_diff);
  if (g.texel_failures)
    std::printf("failing texels (allowed: 0.1%% per RDM):\n%s", g.listing.c_str());
  EXPECT_EQ(g.depth_failures, 0) << g.listing;
  EXPECT_EQ(g.mean_failures, 0) << g.listing;
  EXPECT_EQ(g.rdms_over_budget, 0) << g.listing;
}

}  // namespace rdm::test
