// Throughput and cost of every quality knob (docs/performance.md records the results).
//   build/bench/rdm_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <atomic>
#include <map>
#include <random>
#include <thread>

#include "rdm/bake/bake.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/face_light_filter.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

const Scene& scene(const std::string& name) {
  static std::map<std::string, Scene> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, *builtinScene(name)).first;
  return it->second;
}

const char* kScenes[] = {"chess", "island"};

// Probe rays: random directions from every RDM face origin of the scene, as the bake
// shoots them. Counts rays per second over `threads` threads.
void BM_ProbeRays(benchmark::State& state) {
  const Scene& s = scene(kScenes[state.range(0)]);
  const int threads = int(state.range(1));
  VoxelWorld world = buildWorld(s);
  std::vector<glm::vec3> origins;
  for (const RdmId& id : listRdms(world, s.bake)) {
    if (id.level != shared::kDiffuseLevel) continue;
    for (int f = 0; f < 6; ++f) {
      if (!faceSkipped(world, id.slot, f))
        origins.push_back(glm::vec3(id.slot * 16 + glm::ivec3(8) + 8 * shared::faceNormal(f)));
    }
  }
  const int kRaysPerThread = 200000;
  uint64_t total = 0;
  for (auto _ : state) {
    std::atomic<uint64_t> hits{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
      pool.emplace_back([&, t] {
        uint64_t local = 0;
        for (int i = 0; i < kRaysPerThread; ++i) {
          uint32_t key = shared::pathKey(1, uint32_t(t), 0, uint32_t(i), 0);
          glm::vec3 d(shared::randomUniform(key, 0, 0) - 0.5f,
                      shared::randomUniform(key, 0, 1) - 0.5f,
                      shared::randomUniform(key, 0, 2) - 0.5f);
          const glm::vec3& o = origins[i % origins.size()];
          float tt;
          local += traceVoxels(world, FloatRay(o, glm::normalize(d)), tt).hit;
        }
        hits += local;
      });
    }
    for (auto& th : pool) th.join();
    benchmark::DoNotOptimize(hits.load());
    total += uint64_t(kRaysPerThread) * threads;
  }
  state.counters["rays/s"] = benchmark::Counter(double(total), benchmark::Counter::kIsRate);
  state.SetLabel(std::string(kScenes[state.range(0)]) + ", " + std::to_string(threads) +
                 " threads");
}
BENCHMARK(BM_ProbeRays)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void runBake(benchmark::State& state, Scene s, const std::string& label,
             const BakeOptions& o = BakeOptions()) {
  VoxelWorld world = buildWorld(s);
  BakeReport last;
  for (auto _ : state) last = bakeScene(world, s.bake, o).report;
  state.counters["rays/s"] = double(last.rays) / last.seconds;
  state.counters["Mrays"] = double(last.rays) / 1e6;
  state.counters["rel_err_%"] = 100.0 * last.mean_relative_error;
  state.counters["texels"] = double(last.texels);
  state.SetLabel(label);
}

// The built-in scenes at their own settings.
void BM_BakeScene(benchmark::State& state) {
  runBake(state, scene(kScenes[state.range(0)]), kScenes[state.range(0)]);
}
BENCHMARK(BM_BakeScene)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// Quality knobs on chess: samples per texel, hemisphere size, bounces.
void BM_KnobSpp(benchmark::State& state) {
  Scene s = scene("chess");
  s.bake.spp = int(state.range(0));
  runBake(state, s, "chess spp=" + std::to_string(s.bake.spp));
}
BENCHMARK(BM_KnobSpp)
    ->RangeMultiplier(2)
    ->Range(2, 32)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

void BM_KnobHemisphere(benchmark::State& state) {
  Scene s = scene("chess");
  s.bake.max_hemisphere = int(state.range(0));
  runBake(state, s, "chess max_hemisphere=" + std::to_string(s.bake.max_hemisphere));
}
BENCHMARK(BM_KnobHemisphere)
    ->RangeMultiplier(2)
    ->Range(8, 128)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

void BM_KnobBounces(benchmark::State& state) {
  Scene s = scene("island");
  s.bake.max_bounces = int(state.range(0));
  runBake(state, s, "island max_bounces=" + std::to_string(s.bake.max_bounces));
}
BENCHMARK(BM_KnobBounces)
    ->DenseRange(0, 6, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// Effect specialisation: the same bake with every effect compiled in.
void BM_EffectSpecialisation(benchmark::State& state) {
  BakeOptions o;
  o.all_effects = state.range(0) == 1;
  runBake(state, scene("chess"),
          o.all_effects ? "chess, all effects compiled in" : "chess, specialised (no emitter code)",
          o);
}
BENCHMARK(BM_EffectSpecialisation)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

// The face light filter the viewer runs at each upload (rdm/bake/face_light_filter.h): one
// thread, the scene's face light at 1 spp (the filter's cost does not depend on the spp).
void BM_FaceLightFilter(benchmark::State& state) {
  const char* kFilterScenes[] = {"chess", "island", "terrain"};
  const Scene& s = scene(kFilterScenes[state.range(0)]);
  const VoxelWorld world = buildWorld(s);
  const FaceLight light = bakeFaceLight(world, s, {0, 1});
  FaceLightFilter filter;
  filter.threads = 1;
  for (auto _ : state) benchmark::DoNotOptimize(filterFaceLight(world, light, filter));
  state.counters["faces"] = double(light.faceCount());
  state.counters["Mfaces/s"] = benchmark::Counter(double(light.faceCount()) * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(kFilterScenes[state.range(0)]);
}
BENCHMARK(BM_FaceLightFilter)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace rdm

BENCHMARK_MAIN();
