// CPU and Vulkan bakes of the same scene side by side in one run (docs/vulkan.md records
// the results):
//   build/bench/rdm_vulkan_bench --benchmark_counters_tabular=true
// Counters: rays/s (path segments and shadow rays per second, the bake's own count), Mrays,
// seconds per bake; the Vulkan rows also report the device and the setup time (instance,
// device, pipeline compilation, scene upload) included in the seconds.
// BM_BakeVulkan's second argument turns slot-set recording on (record_slot_sets);
// BM_VulkanBakerSecondBake times a second bake on one VulkanBaker (device and pipeline kept).
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>

#include <sys/resource.h>

#include "rdm/bake/bake.h"
#include "rdm/vulkan/vulkan_bake.h"

namespace rdm {
namespace {

// Chess at reduced settings: every level and effect of the full bake, a fraction of the cost;
// terrain at its own hemisphere size and bounces (0 below: the scene's). The naive estimator
// (the only one on Vulkan) on both backends.
struct Case {
  const char* name;
  const char* scene;
  int spp, max_hemisphere, max_bounces;
};
const Case kCases[] = {{"chess spp=4 S<=16", "chess", 4, 16, 3},
                       {"chess spp=16 S<=32", "chess", 16, 32, 3},
                       {"terrain spp=4", "terrain", 4, 0, 0}};

const Scene& scene(const Case& c) {
  static std::map<const Case*, Scene> cache;
  auto it = cache.find(&c);
  if (it == cache.end()) {
    Scene s = *builtinScene(c.scene);
    s.bake.spp = c.spp;
    if (c.max_hemisphere > 0) s.bake.max_hemisphere = c.max_hemisphere;
    if (c.max_bounces > 0) s.bake.max_bounces = c.max_bounces;
    s.bake.estimator = Estimator::kNaive;
    it = cache.emplace(&c, s).first;
  }
  return it->second;
}

// CPU time of the whole process (all threads, lavapipe's included): on a shared machine
// rays per CPU-second compares the backends' efficiency when wall time is disturbed.
double processCpuSeconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void report(benchmark::State& state, const BakeReport& r, const std::string& label,
            double cpu_seconds) {
  state.counters["rays/s"] = r.seconds > 0 ? double(r.rays) / r.seconds : 0.0;
  state.counters["rays/cpu_s"] = cpu_seconds > 0 ? double(r.rays) / cpu_seconds : 0.0;
  state.counters["Mrays"] = double(r.rays) / 1e6;
  state.counters["seconds"] = r.seconds;
  state.counters["texels"] = double(r.texels);
  state.SetLabel(label);
}

void BM_BakeCpu(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const Scene& s = scene(c);
  VoxelWorld world = buildWorld(s);
  BakeOptions o;  // all cores
  BakeReport last;
  double cpu = 0.0;
  for (auto _ : state) {
    double c0 = processCpuSeconds();
    last = bakeScene(world, s.bake, o).report;
    cpu = processCpuSeconds() - c0;
  }
  report(state, last, std::string("cpu, ") + c.name, cpu);
}
BENCHMARK(BM_BakeCpu)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// One Vulkan bake, its process CPU-seconds in `cpu`; false (the benchmark skipped with the
// error) when it fails.
bool bakeVulkanTimed(benchmark::State& state, const VoxelWorld& world, const BakeSettings& bake,
                     const VulkanBakeOptions& o, BakeReport& last, double& cpu) {
  const double c0 = processCpuSeconds();
  auto r = bakeSceneVulkan(world, bake, o);
  cpu = processCpuSeconds() - c0;
  if (!r) {
    state.SkipWithError(r.error().c_str());
    return false;
  }
  last = r->report;
  return true;
}

// Arguments: case, record_slot_sets (0 or 1).
void BM_BakeVulkan(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const Scene& s = scene(c);
  VoxelWorld world = buildWorld(s);
  VulkanBakeOptions o;
  o.record_slot_sets = state.range(1) != 0;
  VulkanBakeInfo info;
  o.info = &info;
  BakeReport last;
  double cpu = 0.0;
  for (auto _ : state) {
    if (!bakeVulkanTimed(state, world, s.bake, o, last, cpu)) return;
  }
  report(state, last,
         "vulkan " + info.device.name + ", " + c.name + (o.record_slot_sets ? ", recording" : ""),
         cpu);
  state.counters["setup_s"] = info.setup_seconds;
  state.counters["dispatches"] = double(info.dispatches);
}
BENCHMARK(BM_BakeVulkan)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// A built-in scene at its own settings (prefiltered estimator), face light aside, on both
// backends: prefilter_s is the Vulkan bake's prefilter pass (upload, dispatch, read-back).
const char* const kDefaultScenes[] = {"chess", "island", "terrain"};

void BM_BakeDefaults(benchmark::State& state) {
  const Scene s = *builtinScene(kDefaultScenes[state.range(0)]);
  const bool vulkan = state.range(1) != 0;
  VoxelWorld world = buildWorld(s);
  VulkanBakeOptions o;
  VulkanBakeInfo info;
  o.info = &info;
  BakeReport last;
  double cpu = 0.0;
  for (auto _ : state) {
    if (vulkan) {
      if (!bakeVulkanTimed(state, world, s.bake, o, last, cpu)) return;
    } else {
      const double c0 = processCpuSeconds();
      last = bakeScene(world, s.bake, BakeOptions{}).report;
      cpu = processCpuSeconds() - c0;
    }
  }
  report(state, last, std::string(vulkan ? "vulkan " : "cpu ") + kDefaultScenes[state.range(0)],
         cpu);
  state.counters["prefilter_s"] = info.prefilter_seconds;
  state.counters["cpu_s"] = cpu;
}
BENCHMARK(BM_BakeDefaults)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// The second bake on one VulkanBaker: setup_s is then the scene upload alone; first_setup_s
// is the first bake's (device, instance and pipeline creation included).
void BM_VulkanBakerSecondBake(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const Scene& s = scene(c);
  VoxelWorld world = buildWorld(s);
  const std::vector<RdmId> rdms = listRdms(world, s.bake);
  VulkanBakeOptions o;
  VulkanBakeInfo info;
  o.info = &info;
  const auto t0 = std::chrono::steady_clock::now();
  auto baker = VulkanBaker::create(o.device);
  if (!baker) {
    state.SkipWithError(baker.error().c_str());
    return;
  }
  auto first = (*baker)->bake(world, s.bake, rdms, o);
  const double created =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!first) {
    state.SkipWithError(first.error().c_str());
    return;
  }
  const double first_setup = created - first->report.seconds + info.setup_seconds;
  BakeReport last;
  for (auto _ : state) {
    auto r = (*baker)->bake(world, s.bake, rdms, o);
    if (!r) {
      state.SkipWithError(r.error().c_str());
      return;
    }
    last = r->report;
  }
  report(state, last, "vulkan " + info.device.name + ", " + c.name + ", second bake", 0.0);
  state.counters["setup_s"] = info.setup_seconds;
  state.counters["first_setup_s"] = first_setup;
}
BENCHMARK(BM_VulkanBakerSecondBake)
    ->DenseRange(0, 0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace rdm

BENCHMARK_MAIN();
