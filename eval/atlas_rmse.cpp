// atlas_rmse REF_DIR TEST_DIR [--json OUT.json]
//
// Compares two RDM atlases (atlas.exr pages + index.json, as written by `rdm bake` or
// fetched from `rdm serve`) per RDM, matching RDMs by (slot, level) through the indexes, so
// tiles and page layouts may differ. Where the hemisphere sizes differ (a max_hemisphere
// sweep), every reference texel is compared with the test texel that covers its hemi-oct
// position (nearest, i.e. test texel floor(i * S_test / S_ref)), so the error includes what
// the lower resolution loses. Faces whose reference texels are all zero (RGB and Z: skipped
// faces, faces whose origin lies inside a neighbour) are left out of the statistics.
//
// Prints one JSON object: RMSE of linear RGB over the compared texels, RMSE after Reinhard
// c/(1+c), the reference's RMS (for a relative error), the mean difference (test minus
// reference, absolute and relative to the reference's mean: a bias), the worst RDM, counts of RDMs
// compared, missing and bit-identical (all four channels of every texel of every face).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas.h"

namespace {

using Atlas = rdm::LoadedAtlas;

bool loadAtlas(const std::string& dir, Atlas& atlas) {
  auto loaded = rdm::readAtlasOutputs(dir);
  if (!loaded) return std::fprintf(stderr, "atlas_rmse: %s\n", loaded.error().c_str()), false;
  atlas = std::move(*loaded);
  return true;
}

using Key = std::tuple<int, int, int, int>;
Key keyOf(const rdm::RdmId& id) {
  return {id.slot.x, id.slot.y, id.slot.z, id.level};
}

// Texel (i, j) of face `face`; an unstored face reads as 0.
const float* texel(const Atlas& a, const rdm::AtlasEntry& e, int face, int i, int j) {
  static constexpr float kZero[4] = {0, 0, 0, 0};
  const rdm::FaceTile& t = e.faces[size_t(face)];
  if (!t.stored()) return kZero;
  const rdm::Image& page = a.pages[size_t(t.page)];
  return &page.pixels[(size_t(t.y + j) * page.width + size_t(t.x + i)) * 4];
}

double reinhard(double c) {
  return c > 0 ? c / (1.0 + c) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("RMSE between two atlases, RDM by RDM", "atlas_rmse");
  app.option_defaults()->always_capture_default();
  std::string json_path;
  std::vector<std::string> dirs;
  app.add_option("REF_DIR TEST_DIR", dirs, "the two atlas directories")->required()->expected(2);
  app.add_option("--json", json_path, "also write the numbers as JSON here");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  Atlas ref, test;
  if (!loadAtlas(dirs[0], ref) || !loadAtlas(dirs[1], test)) return 1;
  std::map<Key, const rdm::AtlasEntry*> test_entries;
  for (const auto& e : test.layout.entries) test_entries[keyOf(e.id)] = &e;

  double sum_sq = 0, sum_sq_tm = 0, sum_ref_sq = 0, worst_rmse = 0;
  double sum_diff = 0, sum_ref = 0;  // of test - reference, and of the reference (bias)
  unsigned long long texels = 0;
  int compared = 0, missing = 0, identical = 0, size_mismatch = 0;
  std::string worst;
  std::map<int, std::pair<double, unsigned long long>> per_level;  // level -> (sum_sq, texels)
  for (const auto& e : ref.layout.entries) {
    auto it = test_entries.find(keyOf(e.id));
    if (it == test_entries.end()) {
      ++missing;
      continue;
    }
    const rdm::AtlasEntry& t = *it->second;
    test_entries.erase(it);
    ++compared;
    const int S = e.id.size, St = t.id.size;
    if (S != St) ++size_mismatch;
    bool same = S == St;
    double rdm_sq = 0;
    unsigned long long rdm_n = 0;
    for (int f = 0; f < 6; ++f) {
      bool any = false;
      for (int j = 0; j < S && !any; ++j)
        for (int i = 0; i < S && !any; ++i) {
          const float* r = texel(ref, e, f, i, j);
          any = r[0] != 0 || r[1] != 0 || r[2] != 0 || r[3] != 0;
        }
      for (int j = 0; j < S; ++j) {
        for (int i = 0; i < S; ++i) {
          const float* r = texel(ref, e, f, i, j);
          const float* q =
              texel(test, t, f, int((long long)i * St / S), int((long long)j * St / S));
          if (same && std::memcmp(r, q, 4 * sizeof(float)) != 0) same = false;
          if (!any) continue;
          for (int c = 0; c < 3; ++c) {
            const double d = double(q[c]) - double(r[c]);
            const double dt = reinhard(q[c]) - reinhard(r[c]);
            rdm_sq += d * d;
            sum_diff += d, sum_ref += double(r[c]);
            sum_sq_tm += dt * dt;
            sum_ref_sq += double(r[c]) * double(r[c]);
          }
          ++rdm_n;
        }
      }
    }
    if (same) ++identical;
    sum_sq += rdm_sq;
    texels += rdm_n;
    per_level[e.id.level].first += rdm_sq;
    per_level[e.id.level].second += rdm_n;
    if (rdm_n > 0) {
      const double r = std::sqrt(rdm_sq / (3.0 * double(rdm_n)));
      if (r > worst_rmse) {
        worst_rmse = r;
        worst = std::to_string(e.id.slot.x) + "," + std::to_string(e.id.slot.y) + "," +
                std::to_string(e.id.slot.z) + "/" + std::to_string(e.id.level);
      }
    }
  }
  const int extra = int(test_entries.size());
  const double n = 3.0 * double(texels);
  nlohmann::json out = {{"reference", dirs[0]},
                        {"test", dirs[1]},
                        {"rdms_reference", ref.layout.entries.size()},
                        {"rdms_compared", compared},
                        {"rdms_missing_in_test", missing},
                        {"rdms_extra_in_test", extra},
                        {"rdms_size_mismatch", size_mismatch},
                        {"rdms_bit_identical", identical},
                        {"rdms_different", compared - identical},
                        {"bit_identical", missing == 0 && extra == 0 && identical == compared},
                        {"texels_compared", texels},
                        {"rmse", texels ? std::sqrt(sum_sq / n) : 0.0},
                        {"rmse_reinhard", texels ? std::sqrt(sum_sq_tm / n) : 0.0},
                        {"reference_rms", texels ? std::sqrt(sum_ref_sq / n) : 0.0},
                        {"relative_rmse", sum_ref_sq > 0 ? std::sqrt(sum_sq / sum_ref_sq) : 0.0},
                        {"mean_difference", texels ? sum_diff / n : 0.0},
                        {"relative_mean_difference", sum_ref != 0 ? sum_diff / sum_ref : 0.0},
                        {"worst_rdm", worst},
                        {"worst_rdm_rmse", worst_rmse}};
  nlohmann::json levels = nlohmann::json::object();
  for (const auto& [level, v] : per_level)
    levels[std::to_string(level)] = {
        {"texels", v.second},
        {"rmse", v.second ? std::sqrt(v.first / (3.0 * double(v.second))) : 0.0}};
  out["per_level"] = levels;
  const std::string text = out.dump(1);
  std::printf("%s\n", text.c_str());
  if (!json_path.empty()) {
    std::ofstream f(json_path);
    f << text << "\n";
    if (!f) return std::fprintf(stderr, "atlas_rmse: cannot write %s\n", json_path.c_str()), 1;
  }
  return 0;
}
