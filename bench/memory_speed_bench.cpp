// The prefilter and the bake's writers against memcpy and a plain write (issue 42 item 3;
// docs/performance.md, "Prefilter and writing against memcpy").
//   build/bench/rdm_memory_bench --benchmark_counters_tabular=true
// Each iteration times the pass, then a memcpy of the pass's bytes, then (writers) a plain
// write + fsync of the file bytes the pass wrote, alternately, so the three share the
// machine's load. Counters: MB/s of the pass (bytes / wall s), cpu_MB/s (bytes / CPU-s of the
// whole process, OpenEXR's pool included), memcpy_MB/s, ratio = MB/s / memcpy_MB/s and, for
// writers, file_MB/s (file bytes / wall s of the pass) beside plain_MB/s (the same file bytes
// written with write + fsync). RDM_BENCH_DIR (default /tmp) is where the files go.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <random>

#include "rdm/atlas/atlas.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/atlas/slot_sets_file.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/face_map.h"
#include "rdm/image/exr_io.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

const char* kScenes[] = {"chess", "island", "terrain"};

// A built-in scene baked at its own settings (slot sets recorded, as `rdm bake` does), its
// face light and its atlas layout: what the writers write.
struct Baked {
  Scene scene;
  BakeResult bake;
  FaceLight light;
  AtlasLayout layout;
};

const Baked& baked(int scene) {
  static std::map<int, Baked> cache;
  auto it = cache.find(scene);
  if (it != cache.end()) return it->second;
  Baked& b = cache[scene];
  b.scene = *builtinScene(kScenes[scene]);
  const VoxelWorld world = buildWorld(b.scene);
  BakeOptions options;
  options.record_slot_sets = true;
  b.bake = bakeScene(world, b.scene.bake, options);
  FaceLightOptions light;
  light.spp = b.scene.face_light_spp;
  b.light = bakeFaceLight(world, b.scene, light);
  std::vector<RdmId> ids;
  for (const RdmData& d : b.bake.rdms) ids.push_back(d.id);
  b.layout = packCanonical(ids, storedFacesOf(b.bake.rdms));
  return b;
}

std::string benchDir(const std::string& name) {
  const char* root = std::getenv("RDM_BENCH_DIR");
  const std::string dir = std::string(root ? root : "/tmp") + "/rdm_memory_bench/" + name;
  std::filesystem::create_directories(dir);
  return dir;
}

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Cost {
  double wall = 0.0, cpu = 0.0;
};

template <class F>
Cost timeOnce(F&& f) {
  const double wall = wallSeconds(), cpu = processCpuSeconds();
  f();
  return {wallSeconds() - wall, processCpuSeconds() - cpu};
}

// memcpy of `bytes` between two buffers touched beforehand.
class Memcpy {
 public:
  explicit Memcpy(size_t bytes) : src_(bytes, 1), dst_(bytes, 0) {}
  void run() {
    std::memcpy(dst_.data(), src_.data(), src_.size());
    benchmark::DoNotOptimize(dst_.data());
    benchmark::ClobberMemory();
  }

 private:
  std::vector<char> src_, dst_;
};

// write + fsync + close of `bytes` bytes to a new file in `dir`: what the disk allows.
void plainWrite(const std::string& dir, const std::string& bytes) {
  const std::string path = dir + "/plain.bin";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) std::abort();
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) std::abort();
    done += size_t(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) std::abort();
}

std::string fileBytes(const std::string& path) {
  std::string bytes(std::filesystem::file_size(path), '\0');
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::read(fd, bytes.data(), bytes.size()) != ssize_t(bytes.size())) std::abort();
  ::close(fd);
  return bytes;
}

void nothing() {}

// Runs `pass` and a memcpy of `bytes` alternately; with `dir`, also a plain write of the
// bytes of `files` (in `dir`, as the pass left them) and file_MB/s of the pass. `setup` runs
// untimed before each pass.
template <class Pass, class Setup = void (*)()>
void againstMemcpy(benchmark::State& state, size_t bytes, Pass pass, const std::string& dir = {},
                   const std::vector<std::string>& files = {}, Setup setup = nothing) {
  Memcpy copy(bytes);
  setup(), pass(), copy.run();  // warm-up: kernels built, pages touched
  std::string written;
  for (const std::string& f : files) written += fileBytes(dir + "/" + f);
  Cost total, copied, plain;
  for (auto _ : state) {
    setup();
    const Cost c = timeOnce(pass);
    total.wall += c.wall, total.cpu += c.cpu;
    copied.wall += timeOnce([&] { copy.run(); }).wall;
    if (!written.empty()) plain.wall += timeOnce([&] { plainWrite(dir, written); }).wall;
    state.SetIterationTime(c.wall);
  }
  const double n = double(state.iterations()), mb = 1e-6 * double(bytes) * n;
  state.counters["bytes"] = double(bytes);
  state.counters["MB/s"] = mb / total.wall;
  state.counters["cpu_MB/s"] = mb / total.cpu;
  state.counters["memcpy_MB/s"] = mb / copied.wall;
  state.counters["ratio"] = copied.wall / total.wall;
  if (!written.empty()) {
    const double file_mb = 1e-6 * double(written.size()) * n;
    state.counters["file_bytes"] = double(written.size());
    state.counters["file_MB/s"] = file_mb / total.wall;
    state.counters["plain_MB/s"] = file_mb / plain.wall;
  }
}

// A face map of the scene's largest size with varied texels: the kernels' cost does not
// depend on the values.
FaceMap noisyMap(int size) {
  FaceMap map;
  map.map = std::make_unique<RadianceMap>(size);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i)
      map.map->set(i, j, glm::vec3(u(rng), u(rng), u(rng)), glm::vec3(0.01f * u(rng)));
  map.map->buildMips();
  return map;
}

// Every rough level (1..6) of one face derived from its map, as bake.cpp's bakeFromMap does.
// Bytes: per tap the KernelTap (8) and the mean and variance it reads (12 + 12); per output
// texel its kernel's begin (4) and the mean and variance written (12 + 12).
void BM_Prefilter(benchmark::State& state) {
  const Scene s = *builtinScene(kScenes[state.range(0)]);
  const int base = shared::hemisphereSize(0, s.bake.max_hemisphere);
  const FaceMap map = noisyMap(base);
  size_t bytes = 0, texels = 0;
  for (int level = 1; level < shared::kDiffuseLevel; ++level) {
    const int size = shared::hemisphereSize(level, s.bake.max_hemisphere);
    const PrefilterKernel& k = prefilterKernel(level, size, base);
    bytes += k.taps.size() * (sizeof(KernelTap) + 24) + size_t(size * size) * (4 + 24);
    texels += size_t(size * size);
  }
  std::vector<glm::vec3> out(2 * texels);
  againstMemcpy(state, bytes, [&] {
    size_t o = 0;
    for (int level = 1; level < shared::kDiffuseLevel; ++level) {
      const int size = shared::hemisphereSize(level, s.bake.max_hemisphere);
      const FaceMapDerivation derive(map, level, size);
      for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i, o += 2) derive.texel(i, j, out[o], out[o + 1]);
    }
    benchmark::DoNotOptimize(out.data());
  });
  state.SetLabel(std::string(kScenes[state.range(0)]) + ", map " + std::to_string(base));
}
BENCHMARK(BM_Prefilter)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMicrosecond);

// Raw bytes of the atlas pages (R, G, B, Z float32): what the page writer compresses.
size_t pageBytes(const AtlasLayout& layout) {
  size_t bytes = 0;
  for (const AtlasPage& p : layout.pages) bytes += size_t(p.width) * size_t(p.height) * 16;
  return bytes;
}

std::vector<std::string> pageFiles(const AtlasLayout& layout, std::string (*name)(int)) {
  std::vector<std::string> files;
  for (size_t p = 0; p < layout.pages.size(); ++p) files.push_back(name(int(p)));
  return files;
}

// The pages in memory, assembled once: OpenEXR's encoding alone (ZIP, 16 rows a chunk).
void BM_EncodeAtlasPages(benchmark::State& state) {
  const Baked& b = baked(int(state.range(0)));
  const std::vector<Image> pages = assembleAtlas(b.layout, b.bake.rdms);
  againstMemcpy(state, pageBytes(b.layout), [&] {
    for (const Image& page : pages) benchmark::DoNotOptimize(encodeExr(page, kRgbzChannels));
  });
  state.SetLabel(kScenes[state.range(0)]);
}
BENCHMARK(BM_EncodeAtlasPages)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond);

// writeAtlasOutputs: digests, page assembly, encoding, the files and the two indexes.
void BM_WriteAtlas(benchmark::State& state) {
  const Baked& b = baked(int(state.range(0)));
  const std::string dir = benchDir("atlas");
  againstMemcpy(
      state, pageBytes(b.layout),
      [&] {
        if (!writeAtlasOutputs(dir, b.layout, b.bake.rdms)) std::abort();
      },
      dir, pageFiles(b.layout, atlasPageFileName));
  state.SetLabel(kScenes[state.range(0)]);
}
BENCHMARK(BM_WriteAtlas)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond);

// writeNoiseMaps: bytes are the pages' raw float32 noise values (4 per texel).
void BM_WriteNoise(benchmark::State& state) {
  const Baked& b = baked(int(state.range(0)));
  const std::string dir = benchDir("noise");
  againstMemcpy(
      state, pageBytes(b.layout) / 4,
      [&] {
        if (!writeNoiseMaps(dir, b.layout, MemoryRdmSource(b.bake.rdms))) std::abort();
      },
      dir, pageFiles(b.layout, noisePageFileName));
  state.SetLabel(kScenes[state.range(0)]);
}
BENCHMARK(BM_WriteNoise)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond);

// writeFaceLight: bytes are the file's.
void BM_WriteFaceLight(benchmark::State& state) {
  const Baked& b = baked(int(state.range(0)));
  const std::string dir = benchDir("face_light");
  const std::string path = dir + "/face_light.bin";
  if (!writeFaceLight(path, b.light)) std::abort();
  againstMemcpy(state, std::filesystem::file_size(path),
                [&] {
                  if (!writeFaceLight(path, b.light)) std::abort();
                },
                dir, {"face_light.bin"});
  state.SetLabel(kScenes[state.range(0)]);
}
BENCHMARK(BM_WriteFaceLight)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond);

// writeSlotSetsFile (rdms.bin): bytes are the file's; the records' copy is not timed.
void BM_WriteSlotSets(benchmark::State& state) {
  const Baked& b = baked(int(state.range(0)));
  const std::string dir = benchDir("slot_sets");
  std::vector<RdmRecord> records;
  for (const RdmData& d : b.bake.rdms) records.push_back(recordOf(d, "bench"));
  if (!writeSlotSetsFile(dir, records)) std::abort();
  std::vector<RdmRecord> copy;
  againstMemcpy(
      state, std::filesystem::file_size(dir + "/" + kRdmRecordsFile),
      [&] {
        if (!writeSlotSetsFile(dir, std::move(copy))) std::abort();
      },
      dir, {kRdmRecordsFile}, [&] { copy = records; });
  state.SetLabel(kScenes[state.range(0)]);
}
BENCHMARK(BM_WriteSlotSets)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rdm

BENCHMARK_MAIN();
