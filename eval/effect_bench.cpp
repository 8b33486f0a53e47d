// effect_bench [--scene NAME] [--spp N] [--max-hemisphere S] [--max-bounces B] [--reps R]
//              [--threads T]   (--help lists the defaults)
//
// Bake time of one scene with effect specialisation (the default: only the effects the scene
// holds are compiled into the path tracer) and with every effect compiled in
// (BakeOptions::all_effects), alternating, R repetitions each. The same comparison as
// bench/bake_bench.cpp's BM_EffectSpecialisation, for any scene and settings. Prints JSON.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/bake/bake.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

int main(int argc, char** argv) {
  CLI::App app("bake time with and without effect specialisation, as JSON", "effect_bench");
  app.option_defaults()->always_capture_default();
  std::string scene_name = "chess";
  int spp = 0, max_hemisphere = 0, max_bounces = -1, reps = 3, threads = 0;
  app.add_option("--scene", scene_name, "built-in scene or scene file");
  app.add_option("--spp", spp, "samples per texel (0: the scene's)")->check(CLI::NonNegativeNumber);
  app.add_option("--max-hemisphere", max_hemisphere, "hemisphere cap S (0: the scene's)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-bounces", max_bounces, "bounces (-1: the scene's)")
      ->check(CLI::Range(-1, 64));
  app.add_option("--reps", reps, "repetitions of each variant")->check(CLI::Range(1, 1000));
  app.add_option("--threads", threads, "bake threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  auto scene = rdm::loadSceneByNameOrPath(scene_name);
  if (!scene) return std::fprintf(stderr, "effect_bench: %s\n", scene.error().c_str()), 1;
  if (spp > 0) scene->bake.spp = spp;
  if (max_hemisphere > 0) scene->bake.max_hemisphere = max_hemisphere;
  if (max_bounces >= 0) scene->bake.max_bounces = max_bounces;
  if (auto s = rdm::validateScene(*scene); !s)
    return std::fprintf(stderr, "effect_bench: %s\n", s.message().c_str()), 1;
  rdm::VoxelWorld world = rdm::buildWorld(*scene);
  std::vector<double> secs[2];
  uint64_t rays[2] = {0, 0};
  std::string simulated, skipped;
  for (int r = 0; r < reps; ++r) {
    for (int all = 0; all < 2; ++all) {
      rdm::BakeOptions o;
      o.threads = threads;
      o.all_effects = all == 1;
      rdm::BakeReport rep = rdm::bakeScene(world, scene->bake, o).report;
      secs[all].push_back(rep.seconds);
      rays[all] = rep.rays;
      simulated = rep.effects.describeSimulated();
      skipped = rep.effects.describeSkipped();
    }
  }
  auto summary = [&](int k) {
    std::vector<double> s = secs[k];
    std::sort(s.begin(), s.end());
    double mean = 0;
    for (double x : s) mean += x / double(s.size());
    return nlohmann::json{{"seconds", secs[k]},
                          {"min_seconds", s.front()},
                          {"mean_seconds", mean},
                          {"median_seconds", s[s.size() / 2]},
                          {"rays", rays[k]},
                          {"rays_per_second", s.front() > 0 ? double(rays[k]) / s.front() : 0.0}};
  };
  nlohmann::json out = {{"scene", scene_name},
                        {"spp", scene->bake.spp},
                        {"max_hemisphere", scene->bake.max_hemisphere},
                        {"max_bounces", scene->bake.max_bounces},
                        {"reps", reps},
                        {"effects_simulated", simulated},
                        {"effects_skipped", skipped},
                        {"specialised", summary(0)},
                        {"all_effects", summary(1)}};
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}
