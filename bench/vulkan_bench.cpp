// CPU and Vulkan bakes of the same scene side by side in one run (docs/vulkan.md records
// the results):
//   build/bench/rdm_vulkan_bench --benchmark_counters_tabular=true
// Counters: rays/s (path segments and shadow rays per second, the bake's own count), Mrays,
// seconds per bake; the Vulkan rows also report the device and the setup time (instance,
// device, pipeline compilation, scene upload) included in the seconds.
#include <benchmark/benchmark.h>

#include <map>

#include <sys/resource.h>

#include "rdm/bake.h"
#include "rdm/vulkan_bake.h"

namespace rdm {
namespace {

// Chess at reduced settings: every level and effect of the full bake, a fraction of the cost.
struct Case {
  const char* name;
  int spp, max_hemisphere, max_bounces;
};
const Case kCases[] = {{"chess spp=4 S<=16", 4, 16, 3}, {"chess spp=16 S<=32", 16, 32, 3}};

const Scene& chess(const Case& c) {
  static std::map<const Case*, Scene> cache;
  auto it = cache.find(&c);
  if (it == cache.end()) {
    Scene s = *builtinScene("chess");
    s.bake.spp = c.spp;
    s.bake.max_hemisphere = c.max_hemisphere;
    s.bake.max_bounces = c.max_bounces;
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
  const Scene& s = chess(c);
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
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

void BM_BakeVulkan(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const Scene& s = chess(c);
  VoxelWorld world = buildWorld(s);
  VulkanBakeOptions o;
  VulkanBakeInfo info;
  o.info = &info;
  BakeReport last;
  double cpu = 0.0;
  for (auto _ : state) {
    double c0 = processCpuSeconds();
    auto r = bakeSceneVulkan(world, s.bake, o);
    cpu = processCpuSeconds() - c0;
    if (!r) {
      state.SkipWithError(r.error().c_str());
      return;
    }
    last = r->report;
  }
  report(state, last, "vulkan " + info.device.name + ", " + c.name, cpu);
  state.counters["setup_s"] = info.setup_seconds;
  state.counters["dispatches"] = double(info.dispatches);
}
BENCHMARK(BM_BakeVulkan)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace rdm

BENCHMARK_MAIN();
