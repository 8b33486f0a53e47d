// The project's voxel walks (the CPU's traceVoxels, the kernel's shared steps and the SIMD
// stream traceVoxelStream) against Embree 3 (rtcIntersect1, and rtcIntersect16 packets) on the
// same rays, in one process, on the dense `terrain` built-in (docs/performance.md records the
// results). Rays per CPU-second of the tracing thread, so the machine's load cancels out; hits
// are compared ray by ray.
//   build/bench/rdm_traversal_vs_embree [--rays N] [--reps N]
//       [--only rdm|shared|stream|embree|embree16] [--disable-targets HWY_BITS]
// --disable-targets takes Highway's target bits (0x180: no AVX-512; 0x380: nor AVX2).
#include <embree3/rtcore.h>
#include <hwy/targets.h>
#include <numbers>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rdm/base/parallel.h"
#include "rdm/trace/shared_walk.h"
#include "rdm/trace/traversal.h"
#include "rdm/trace/voxel_stream.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

struct Rays {
  std::vector<glm::vec3> o, d;
};

double threadCpuSeconds() {
  return 1e-9 * double(threadCpuNanoseconds());
}

// Origins uniform inside uniformly chosen empty voxels; directions uniform on the sphere.
Rays probeRays(const VoxelWorld& world, int count) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const glm::ivec3 e = world.voxelExtent();
  Rays rays;
  while (int(rays.o.size()) < count) {
    glm::ivec3 v(int(u(rng) * e.x), int(u(rng) * e.y), int(u(rng) * e.z));
    v = glm::min(v, e - 1);
    if (world.voxelAt(v)) continue;
    float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng);
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    rays.o.push_back(glm::vec3(v) + glm::vec3(u(rng), u(rng), u(rng)));
    rays.d.push_back(glm::vec3(r * std::cos(phi), z, r * std::sin(phi)));
  }
  return rays;
}

// A pinhole at the scene's first camera (slot units), side x side pixels in scanline order.
Rays cameraRays(const Camera& cam, int side) {
  const glm::vec3 pos(cam.position * 16.0), target(cam.target * 16.0);
  const glm::vec3 fwd = glm::normalize(target - pos);
  const glm::vec3 right = glm::normalize(glm::cross(fwd, glm::vec3(0, 1, 0)));
  const glm::vec3 up = glm::cross(right, fwd);
  const float h = std::tan(float(cam.fov_deg) * 0.5f * std::numbers::pi_v<float> / 180.0f);
  Rays rays;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      float sx = (2.0f * (x + 0.5f) / side - 1.0f) * h, sy = (1.0f - 2.0f * (y + 0.5f) / side) * h;
      rays.o.push_back(pos);
      rays.d.push_back(glm::normalize(fwd + sx * right + sy * up));
    }
  return rays;
}

// The exposed voxel faces as Embree quads; quad_voxel[primID] is the solid voxel.
struct EmbreeWorld {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<glm::ivec3> quad_voxel;
  ~EmbreeWorld() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

void buildEmbree(const VoxelWorld& world, EmbreeWorld& out) {
  std::vector<float> verts;
  const glm::ivec3 e = world.voxelExtent();
  for (int z = 0; z < e.z; ++z)
    for (int y = 0; y < e.y; ++y)
      for (int x = 0; x < e.x; ++x) {
        const glm::ivec3 v(x, y, z);
        if (!world.voxelAt(v)) continue;
        for (int f = 0; f < 6; ++f) {
          const glm::ivec3 n = shared::faceNormal(f);
          if (world.voxelAt(v + n)) continue;
          const int a = f / 2, b = (a + 1) % 3, c = (a + 2) % 3;
          const int corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          for (const auto& k : corners) {
            glm::ivec3 p = v;
            p[a] += n[a] > 0 ? 1 : 0;
            p[b] += k[0], p[c] += k[1];
            verts.insert(verts.end(), {float(p.x), float(p.y), float(p.z)});
          }
          out.quad_voxel.push_back(v);
        }
      }
  out.device = rtcNewDevice(nullptr);
  out.scene = rtcNewScene(out.device);
  rtcSetSceneBuildQuality(out.scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(out.device, RTC_GEOMETRY_TYPE_QUAD);
  const size_t quads = out.quad_voxel.size();
  auto* vb = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, quads * 4));
  std::memcpy(vb, verts.data(), verts.size() * sizeof(float));
  auto* ib = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 16, quads));
  for (size_t i = 0; i < quads * 4; ++i) ib[i] = unsigned(i);
  rtcCommitGeometry(g);
  rtcAttachGeometry(out.scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(out.scene);
}

constexpr int kMiss = std::numeric_limits<int>::min();

// Linear index of the hit voxel per ray in [begin, end), kMiss on a miss; `trace` is
// traceVoxels (the CPU's walk) or traceSharedWalk (the kernel's and the viewer's steps).
template <class Trace>
double traceOurs(const VoxelWorld& world, const Rays& rays, size_t begin, size_t end,
                 std::vector<int>& hits, Trace trace) {
  const glm::ivec3 e = world.voxelExtent();
  double t0 = threadCpuSeconds();
  for (size_t i = begin; i < end; ++i) {
    float t;
    TraceHit h = trace(world, FloatRay(rays.o[i], rays.d[i]), t);
    hits[i] = h.hit ? h.voxel.x + e.x * (h.voxel.y + e.y * h.voxel.z) : kMiss;
  }
  return threadCpuSeconds() - t0;
}
// The same rays through traceVoxelStream, which walks them a SIMD lane each.
double traceStream(const VoxelWorld& world, const Rays& rays, size_t begin, size_t end,
                   std::vector<int>& hits) {
  const glm::ivec3 e = world.voxelExtent();
  std::vector<FloatRay> batch;
  batch.reserve(end - begin);
  for (size_t i = begin; i < end; ++i) batch.emplace_back(rays.o[i], rays.d[i]);
  std::vector<TraceHit> out(batch.size());
  std::vector<float> t(batch.size());
  double t0 = threadCpuSeconds();
  traceVoxelStream(world, batch, out, t);
  const double seconds = threadCpuSeconds() - t0;
  for (size_t i = begin; i < end; ++i) {
    const TraceHit& h = out[i - begin];
    hits[i] = h.hit ? h.voxel.x + e.x * (h.voxel.y + e.y * h.voxel.z) : kMiss;
  }
  return seconds;
}
TraceHit traceCpuWalk(const VoxelWorld& world, const FloatRay& ray, float& t) {
  return traceVoxels(world, ray, t);
}

double traceEmbree(const VoxelWorld& world, const EmbreeWorld& ew, const Rays& rays, bool coherent,
                   size_t begin, size_t end, std::vector<int>& hits) {
  const glm::ivec3 e = world.voxelExtent();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags =
      coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  double t0 = threadCpuSeconds();
  for (size_t i = begin; i < end; ++i) {
    RTCRayHit rh;
    rh.ray.org_x = rays.o[i].x, rh.ray.org_y = rays.o[i].y, rh.ray.org_z = rays.o[i].z;
    rh.ray.dir_x = rays.d[i].x, rh.ray.dir_y = rays.d[i].y, rh.ray.dir_z = rays.d[i].z;
    rh.ray.tnear = 0.0f, rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.time = 0.0f, rh.ray.mask = ~0u, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(ew.scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      hits[i] = kMiss;
    } else {
      const glm::ivec3 v = ew.quad_voxel[rh.hit.primID];
      hits[i] = v.x + e.x * (v.y + e.y * v.z);
    }
  }
  return threadCpuSeconds() - t0;
}

// Embree's own SIMD over rays: rtcIntersect16 on packets of 16 consecutive rays.
double traceEmbree16(const VoxelWorld& world, const EmbreeWorld& ew, const Rays& rays,
                     bool coherent, size_t begin, size_t end, std::vector<int>& hits) {
  const glm::ivec3 e = world.voxelExtent();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags =
      coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  double t0 = threadCpuSeconds();
  for (size_t first = begin; first < end; first += 16) {
    alignas(64) RTCRayHit16 rh;
    alignas(64) int valid[16];
    for (size_t k = 0; k < 16; ++k) {
      const size_t i = std::min(first + k, end - 1);
      valid[k] = first + k < end ? -1 : 0;
      rh.ray.org_x[k] = rays.o[i].x, rh.ray.org_y[k] = rays.o[i].y, rh.ray.org_z[k] = rays.o[i].z;
      rh.ray.dir_x[k] = rays.d[i].x, rh.ray.dir_y[k] = rays.d[i].y, rh.ray.dir_z[k] = rays.d[i].z;
      rh.ray.tnear[k] = 0.0f, rh.ray.tfar[k] = std::numeric_limits<float>::infinity();
      rh.ray.time[k] = 0.0f, rh.ray.mask[k] = ~0u, rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, ew.scene, &ctx, &rh);
    for (size_t k = 0; k < 16 && first + k < end; ++k) {
      if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
        hits[first + k] = kMiss;
      } else {
        const glm::ivec3 v = ew.quad_voxel[rh.hit.primID[k]];
        hits[first + k] = v.x + e.x * (v.y + e.y * v.z);
      }
    }
  }
  return threadCpuSeconds() - t0;
}

// The three methods alternate on chunks of 20,000 rays, so all see the same machine load;
// each rep traces every ray with each. Reports the median over reps of each rate and of the
// per-rep ratio to Embree.
// --only METHOD: trace with that method alone (for profiling); the others report nothing.
std::string g_only;

void compare(const char* label, const VoxelWorld& world, const EmbreeWorld& ew, const Rays& rays,
             bool coherent, int reps) {
  const size_t n = rays.o.size(), chunk = 20000;
  std::vector<int> ours(n), shared(n), theirs(n), stream(n), theirs16(n);
  std::vector<double> ours_rate, shared_rate, embree_rate, ratio, shared_ratio, stream_rate,
      stream_ratio, embree16_rate, stream16_ratio;
  for (int r = 0; r < reps; ++r) {
    double t_ours = 0.0, t_shared = 0.0, t_embree = 0.0, t_stream = 0.0, t_embree16 = 0.0;
    for (size_t begin = 0; begin < n; begin += chunk) {
      const size_t end = std::min(n, begin + chunk);
      if (g_only.empty() || g_only == "rdm")
        t_ours += traceOurs(world, rays, begin, end, ours, traceCpuWalk);
      if (g_only.empty() || g_only == "shared")
        t_shared += traceOurs(world, rays, begin, end, shared, traceSharedWalk);
      if (g_only.empty() || g_only == "embree")
        t_embree += traceEmbree(world, ew, rays, coherent, begin, end, theirs);
      if (g_only.empty() || g_only == "stream")
        t_stream += traceStream(world, rays, begin, end, stream);
      if (g_only.empty() || g_only == "embree16")
        t_embree16 += traceEmbree16(world, ew, rays, coherent, begin, end, theirs16);
    }
    embree16_rate.push_back(double(n) / t_embree16),
        stream16_ratio.push_back(t_embree16 / t_stream);
    stream_rate.push_back(double(n) / t_stream), stream_ratio.push_back(t_embree / t_stream);
    ours_rate.push_back(double(n) / t_ours), shared_rate.push_back(double(n) / t_shared);
    embree_rate.push_back(double(n) / t_embree);
    ratio.push_back(t_embree / t_ours), shared_ratio.push_back(t_embree / t_shared);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  size_t differ = 0, shared_differ = 0, stream_differ = 0, differ16 = 0, hit = 0;
  for (size_t i = 0; i < n; ++i) {
    differ += ours[i] != theirs[i], hit += ours[i] != kMiss;
    shared_differ += shared[i] != ours[i], stream_differ += stream[i] != ours[i];
    differ16 += theirs16[i] != theirs[i];
  }
  std::printf(
      "%-16s %9.2f M %9.2f M %9.2f M %9.2f M %9.2f M %7.2fx %7.2fx %7.2fx %7.2fx   %zu of %zu "
      "differ from Embree, %zu shared and %zu stream from rdm, %zu Embree16 from Embree, "
      "%.1f %% hit\n",
      label, median(ours_rate) * 1e-6, median(shared_rate) * 1e-6, median(stream_rate) * 1e-6,
      median(embree_rate) * 1e-6, median(embree16_rate) * 1e-6, median(ratio), median(shared_ratio),
      median(stream_ratio), median(stream16_ratio), differ, n, shared_differ, stream_differ,
      differ16, 100.0 * double(hit) / double(n));
}

int run(int argc, char** argv) {
  int count = 1000000, reps = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--rays")) count = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--reps")) reps = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--only")) g_only = argv[i + 1];
    if (!std::strcmp(argv[i], "--disable-targets"))
      hwy::DisableTargets(std::strtoll(argv[i + 1], nullptr, 0));
  }
  Expected<Scene> scene = builtinScene("terrain");
  if (!scene.ok()) {
    std::fprintf(stderr, "%s\n", scene.error().c_str());
    return 1;
  }
  const VoxelWorld world = buildWorld(*scene);
  size_t solid = 0;
  for (const OrientedBlock& b : world.blocks) solid += size_t(b.solid_count);
  const glm::ivec3 e = world.voxelExtent();
  EmbreeWorld ew;
  buildEmbree(world, ew);
  std::printf(
      "terrain: %d x %d x %d voxels, %.1f %% solid, %zu of %zu blocks non-empty, %zu quads\n", e.x,
      e.y, e.z, 100.0 * double(solid) / (double(e.x) * e.y * e.z), world.blocks.size(),
      world.slots.size(), ew.quad_voxel.size());
  std::printf("stream: %d lanes (%s)\n", voxelStreamLanes(), voxelStreamTarget());
  std::printf(
      "%-16s %11s %11s %11s %11s %11s %8s %8s %8s %8s   (rays per CPU-second, median of %d; "
      "ratios to embree, the last to embree16)\n",
      "rays", "rdm", "shared", "stream", "embree", "embree16", "rdm", "shared", "stream", "stream",
      reps);
  const int side = int(std::lround(std::sqrt(double(count))));
  compare("incoherent probe", world, ew, probeRays(world, count), false, reps);
  compare("camera", world, ew, cameraRays(scene->cameras.at(0), side), true, reps);
  return 0;
}

}  // namespace
}  // namespace rdm

int main(int argc, char** argv) {
  return rdm::run(argc, argv);
}
