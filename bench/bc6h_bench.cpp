// BC6H encoding throughput on chess's atlas page (the scene's default bake, 832 x 1088 with
// bc6h packing), all 14 modes (docs/bc6h.md records the results):
//   build/bench/rdm_bc6h_bench --benchmark_counters_tabular=true
// Counters: texels/s (wall), blocks. BM_Bc6hCpu's argument is the thread count (0: one per
// hardware thread); BM_Bc6hVulkan encodes on the default Vulkan device, created once before
// the timing (its creation and pipeline compilation are reported as setup_s), so the time is
// upload, dispatches and read-back.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>

#include "rdm/atlas/atlas.h"
#include "rdm/bake/bake.h"
#include "rdm/image/bc6h.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "rdm/vulkan/vulkan_bc6h.h"

namespace rdm {
namespace {

// Page 0 of chess's bc6h atlas as writeAtlasOutputs encodes it (padded small tiles), baked once.
const Image& chessPage() {
  static const Image page = [] {
    const Scene scene = builtinScene("chess").value();
    const std::vector<RdmData> rdms = bakeScene(buildWorld(scene), scene.bake, {}).rdms;
    std::vector<RdmId> ids;
    for (const RdmData& d : rdms) ids.push_back(d.id);
    const AtlasLayout layout = packCanonical(ids, storedFacesOf(rdms), RadianceFormat::kBc6h);
    Image first = assembleAtlas(layout, rdms)[0];
    padSmallTiles(layout, 0, first);
    return first;
  }();
  return page;
}

void setCounters(benchmark::State& state, const Image& page) {
  const double texels = double(page.width) * double(page.height);
  state.counters["texels/s"] =
      benchmark::Counter(texels * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["blocks"] = texels / 16.0;
}

void BM_Bc6hCpu(benchmark::State& state) {
  const Image& page = chessPage();
  const Bc6hOptions options{Bc6hModeSet::kAll, int(state.range(0))};
  for (auto _ : state) {
    Expected<Bc6hImage> encoded = encodeBc6h(page, options);
    if (!encoded) state.SkipWithError(encoded.error().c_str());
    benchmark::DoNotOptimize(encoded);
  }
  setCounters(state, page);
}
BENCHMARK(BM_Bc6hCpu)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Bc6hVulkan(benchmark::State& state) {
  const Image& page = chessPage();
  const auto start = std::chrono::steady_clock::now();
  static auto encoder = VulkanBc6hEncoder::create("");
  const double setup =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!encoder) {
    state.SkipWithError(encoder.error().c_str());
    return;
  }
  for (auto _ : state) {
    Expected<Bc6hImage> encoded = (*encoder)->encode(page, Bc6hModeSet::kAll);
    if (!encoded) state.SkipWithError(encoded.error().c_str());
    benchmark::DoNotOptimize(encoded);
  }
  setCounters(state, page);
  state.counters["setup_s"] = setup;
  state.SetLabel((*encoder)->device().name);
}
BENCHMARK(BM_Bc6hVulkan)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace rdm

BENCHMARK_MAIN();
