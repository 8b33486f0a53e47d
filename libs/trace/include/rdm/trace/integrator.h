// The path tracer of docs/spec.md section 5, shared by the RDM bake and reference renders.
// Specialised at compile time on the scene's effect set: with kSun false no sun code runs
// (no shadow rays), with kEmitters false no emitter sampling runs. Compiling an absent
// effect in leaves results bit-identical: it only ever adds exact zeros.
#pragma once

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/scene/world.h"
#include "rdm/trace/bsdf.h"
#include "rdm/trace/first_segments.h"
#include "rdm/trace/glass.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sampling.h"

namespace rdm {

struct PathStats {
  uint64_t rays = 0;  // path segments and shadow rays
};

enum class PathOrigin { kRdmFace, kCamera, kFaceLight };

// Where a path starts. A face-light path (docs/spec.md section 3.2) of a face in `slot` draws
// its first direction with pdf `pdf` (cos / pi) beside next-event estimation at its origin with
// the slot's local emitter choice (`local_sum`), so emitters its first segment hits are
// MIS-weighted as at any later vertex; the other origins leave pdf 0.
struct PathStart {
  PathOrigin origin;
  float pdf = 0.0f;
  glm::ivec3 slot{0};
  float local_sum = 0.0f;
  PathStart(PathOrigin o) : origin(o) {}  // NOLINT: every other origin is just its kind
  PathStart(PathOrigin o, float first_pdf, const glm::ivec3& face_slot, float face_local_sum)
      : origin(o), pdf(first_pdf), slot(face_slot), local_sum(face_local_sum) {}
};

// Receives the slots every traced ray passes through (docs/spec.md section 8's full and
// first-segment sets). NoRecorder compiles to nothing.
struct NoRecorder {
  void operator()(int) {}
  void endFirstSegment() {}
  void smoothVertex() {}
};

struct SlotRecorder {
  std::vector<uint32_t>* full;
  std::vector<uint32_t>* first;
  bool in_first = true;
  bool smooth_vertex = false;  // the path met a non-delta vertex
  int last = -1;
  void operator()(int slot) {
    if (slot == last) return;
    last = slot;
    full->push_back(uint32_t(slot));
    if (in_first) first->push_back(uint32_t(slot));
  }
  void endFirstSegment() { in_first = false, last = -1; }
  void smoothVertex() { smooth_vertex = true; }
};

// The same sets as dense bitsets over the grid's linear slot indices: O(1) per slot crossed,
// for grids small enough that a unit can hold one bit per slot (BakeSession decides).
struct SlotBitRecorder {
  uint64_t* full;
  uint64_t* first;
  bool in_first = true;
  bool smooth_vertex = false;
  int last = -1;
  void operator()(int slot) {
    if (slot == last) return;
    last = slot;
    const uint64_t bit = uint64_t(1) << (slot & 63);
    full[slot >> 6] |= bit;
    if (in_first) first[slot >> 6] |= bit;
  }
  void endFirstSegment() { in_first = false, last = -1; }
  void smoothVertex() { smooth_vertex = true; }
};

namespace detail {

inline Frame faceFrame(int face) {
  const shared::ShFrame f = shared::faceFrameOf(face);
  return {f.t, f.b, f.n};
}

inline float powerHeuristic(float a, float b) {
  return shared::misPowerHeuristic(a, b);
}

inline glm::vec3 hitPoint(const FloatRay& ray, float t, const TraceHit& hit) {
  return shared::entryPoint(ray.o, ray.d, t, hit.voxel, hit.axis);
}

template <class Recorder>
TraceHit traceRay(const VoxelWorld& world, const FloatRay& ray, float& t, Recorder& rec) {
  if constexpr (std::is_same_v<std::decay_t<Recorder>, NoRecorder>) {
    return traceVoxels(world, ray, t);
  } else {
    rec.last = -1;
    return traceVoxels(world, ray, t, rec);
  }
}

// What a shadow ray from p along unit l meets past any glass (docs/spec.md section 5,
// "Glass"): glass regions are crossed in a straight line, each multiplying `transmittance` by
// glassCrossing and setting `crossed`; the (kMaxGlassCrossings + 1)-th blocks.
template <class Recorder>
TraceHit traceShadow(const VoxelWorld& world, glm::vec3 p, const glm::vec3& l,
                     glm::vec3& transmittance, bool& crossed, PathStats& stats, Recorder& rec) {
  for (int crossing = 0;; ++crossing) {
    float t = 0.0f;
    ++stats.rays;
    const FloatRay ray(p, l);
    const TraceHit hit = traceRay(world, ray, t, rec);
    if (!hit.hit || hit.started_solid || !isGlass(world, hit.palette) ||
        crossing == kMaxGlassCrossings)
      return hit;
    transmittance *= glassCrossing(world.materials[hit.palette], std::abs(l[hit.axis]));
    crossed = true;
    const glm::vec3 entry = shared::entryPoint(ray.o, ray.d, t, hit.voxel, hit.axis);
    ++stats.rays;
    const GlassExit exit = traceGlass(world, entry, l, [&](int slot) { rec(slot); });
    if (!exit.left) return hit;
    if (exit.into_opaque) {
      TraceHit opaque;
      opaque.hit = true, opaque.voxel = exit.cell, opaque.axis = exit.axis;
      opaque.palette = exit.palette;
      return opaque;
    }
    p = shared::entryPoint(entry, l, exit.t, exit.cell, exit.axis);
  }
}

template <class Recorder>
glm::vec3 sampleSun(const VoxelWorld& world, const Material& m, const Frame& frame,
                    const glm::vec3& v_local, const glm::vec3& p, uint32_t key, uint32_t bounce,
                    PathStats& stats, Recorder& rec) {
  const SunLight& sun = world.sun;
  glm::vec3 l = frameAround(sun.direction)
                    .toWorld(sampleUniformCone(
                        sun.one_minus_cos_max, shared::randomUniform(key, bounce, shared::kDimSun0),
                        shared::randomUniform(key, bounce, shared::kDimSun1)));
  glm::vec3 l_local = frame.toLocal(l);
  if (l_local.z <= 0.0f) return glm::vec3(0.0f);
  glm::vec3 f = evalBsdf(m, v_local, l_local);
  if (f == glm::vec3(0.0f)) return glm::vec3(0.0f);
  glm::vec3 transmittance(1.0f);
  bool crossed = false;
  if (traceShadow(world, p, l, transmittance, crossed, stats, rec).hit) return glm::vec3(0.0f);
  // Through glass only this estimator reaches the sun (tracePath weighs the other 0).
  float w = crossed ? 1.0f : powerHeuristic(sun.pdf, pdfBsdf(m, v_local, l_local));
  return f * sun.irradiance * transmittance * (l_local.z * w);
}

// The emitter chosen for next-event estimation and the point on it (voxel units).
struct EmitterPoint {
  const Emitter* emitter;
  glm::vec3 point;
};
EmitterPoint pickEmitterPoint(const VoxelWorld& world, uint32_t key, uint32_t bounce);
// Contribution of emitter NEE given the shadow ray's hit, past glass of `transmittance` when
// it `crossed` some (then only this estimator reaches the emitter: weight 1).
glm::vec3 emitterContribution(const VoxelWorld& world, const Material& m, const glm::vec3& v_local,
                              const glm::vec3& l_local, const EmitterPoint& e, float dist2,
                              float cos_e, const TraceHit& hit, const glm::vec3& transmittance,
                              bool crossed);

template <class Recorder>
glm::vec3 sampleEmitters(const VoxelWorld& world, const Material& m, const Frame& frame,
                         const glm::vec3& v_local, const glm::vec3& p, uint32_t key,
                         uint32_t bounce, PathStats& stats, Recorder& rec) {
  EmitterPoint e = pickEmitterPoint(world, key, bounce);
  glm::vec3 to = e.point - p;
  float dist2 = glm::dot(to, to);
  if (!(dist2 > 0.0f)) return glm::vec3(0.0f);
  glm::vec3 l = to / std::sqrt(dist2);
  glm::vec3 l_local = frame.toLocal(l);
  float cos_e = -glm::dot(glm::vec3(shared::faceNormal(e.emitter->face)), l);
  if (l_local.z <= 0.0f || cos_e <= 0.0f) return glm::vec3(0.0f);
  if (evalBsdf(m, v_local, l_local) == glm::vec3(0.0f)) return glm::vec3(0.0f);
  glm::vec3 transmittance(1.0f);
  bool crossed = false;
  const TraceHit hit = traceShadow(world, p, l, transmittance, crossed, stats, rec);
  return emitterContribution(world, m, v_local, l_local, e, dist2, cos_e, hit, transmittance,
                             crossed);
}
// Solid-angle pdf with which emitter sampling would pick the emitter face with `radiance`
// seen at squared distance dist2 (voxel units) under cosine cos_e.
float emitterSolidAnglePdf(const VoxelWorld& world, const glm::vec3& radiance, float dist2,
                           float cos_e);

// The face light's local emitter choice (docs/spec.md section 3.2): the CDF mass of the
// emitters of the slots within one slot of `slot`, and the emitter index draw u picks.
float faceLightLocalSum(const VoxelWorld& world, const glm::ivec3& slot);
int pickFaceLightEmitter(const VoxelWorld& world, const glm::ivec3& slot, float local_sum, float u);

// Emitter next-event estimation at a face light's origin `p` on a face with normal `n` in
// `slot` (docs/spec.md section 3.2), with the draws of bounce 0; one shadow ray.
glm::vec3 sampleEmittersAtFace(const VoxelWorld& world, const glm::ivec3& slot, float local_sum,
                               const glm::vec3& n, const glm::vec3& p, uint32_t key,
                               PathStats& stats);

}  // namespace detail

// Radiance arriving at `origin` (voxel units) from unit direction `dir`. The RDM face and face
// light origins exclude direct sunlight on the first segment (docs/spec.md section 3).
// `first`, when given, is the path's first segment already traced (rdm/trace/first_segments.h);
// a recording path takes none, since the stream does not visit slots.
template <bool kSun, bool kEmitters, class Recorder = NoRecorder>
glm::vec3 tracePath(const VoxelWorld& world, int max_bounces, glm::vec3 origin, glm::vec3 dir,
                    uint32_t key, PathStart start, PathStats& stats, Recorder&& rec = Recorder(),
                    const FirstSegment* first = nullptr) {
  glm::vec3 radiance(0.0f), throughput(1.0f);
  bool last_delta = false, any_smooth = false;
  float last_pdf = start.pdf;
  const bool first_weighted = start.origin == PathOrigin::kFaceLight;
  // Glass (docs/spec.md section 5): the ray is inside glass of index glass_ior; since the
  // last vertex with next-event estimation every delta event was a refraction through glass
  // (nee_reaches), at least one (through_glass), so that estimation counted the light.
  // Glass events (entering, leaving, reflecting at glass) count against kMaxGlassEvents, not
  // max_bounces, though each takes the random numbers of its own vertex k.
  bool in_glass = false, nee_reaches = first_weighted, through_glass = false;
  float glass_ior = 1.0f;
  int glass_events = 0;
  for (int k = 1;; ++k) {
    if (in_glass) {
      ++stats.rays;
      const GlassExit exit = traceGlass(world, origin, dir, [&](int slot) { rec(slot); });
      if (!exit.left || exit.into_opaque) break;  // absorbed where glass meets an opaque voxel
      if (++glass_events > kMaxGlassEvents) break;
      const glm::vec3 n(shared::faceNormal(shared::entryFace(exit.axis, dir[exit.axis])));
      const float f = shared::fresnelDielectric(-glm::dot(dir, n), glass_ior);
      origin = shared::entryPoint(origin, dir, exit.t, exit.cell, exit.axis);
      if (shared::randomUniform(key, uint32_t(k), shared::kDimFresnel) < f) {
        dir = glm::reflect(dir, n);  // back into the glass
        nee_reaches = false;
      } else {
        dir = shared::refractDirection(dir, n, glass_ior);
        in_glass = false;
      }
      continue;
    }
    FloatRay ray(origin, dir);
    float t = 0.0f;
    ++stats.rays;
    TraceHit hit;
    if constexpr (std::is_same_v<std::decay_t<Recorder>, NoRecorder>) {
      if (k == 1 && first) {
        hit = first->hit, t = first->t;
      } else {
        hit = traceVoxels(world, ray, t);
      }
    } else {
      RDM_CHECK(first == nullptr);  // the stream does not visit slots
      hit = traceVoxels(world, ray, t, rec);
    }
    if (k == 1) rec.endFirstSegment();
    if (!hit.hit) {
      radiance += throughput * world.sky.radiance(dir);
      if (kSun && world.sun.present && world.sun.inDisc(dir)) {
        float w = k == 1 ? (start.origin == PathOrigin::kCamera ? 1.0f : 0.0f)
                         : (!last_delta ? detail::powerHeuristic(last_pdf, world.sun.pdf)
                                        : (any_smooth ? 0.0f : 1.0f));
        if (w > 0.0f) radiance += throughput * world.sun.radiance * w;
      }
      break;
    }
    if (hit.started_solid) break;
    const Material& m = world.materials[hit.palette];
    const glm::vec3 p = detail::hitPoint(ray, t, hit);
    const Frame frame = detail::faceFrame(shared::entryFace(hit.axis, dir[hit.axis]));
    const glm::vec3 v_local = frame.toLocal(-dir);
    if (m.emissive) {
      float w = last_delta && nee_reaches && through_glass ? 0.0f : 1.0f;
      if (kEmitters && (k > 1 || first_weighted) && !last_delta) {
        float pdf_e = detail::emitterSolidAnglePdf(world, m.emission, t * t, v_local.z);
        if (k == 1)
          pdf_e *= shared::faceLightPickFactor(start.local_sum,
                                               shared::slotsAdjacent(hit.voxel >> 4, start.slot));
        w = detail::powerHeuristic(last_pdf, pdf_e);
      }
      radiance += throughput * m.emission * w;
    }
    if (k - glass_events > max_bounces) break;
    const uint32_t bounce = uint32_t(k);
    if (m.transmission > 0.0f &&
        shared::randomUniform(key, bounce, shared::kDimGlassChoice) < m.transmission) {
      if (++glass_events > kMaxGlassEvents) break;
      // The dielectric: reflection or refraction into the glass (delta events).
      const float f = shared::fresnelDielectric(v_local.z, 1.0f / m.ior);
      if (shared::randomUniform(key, bounce, shared::kDimFresnel) < f) {
        dir = glm::reflect(dir, frame.n);
        nee_reaches = false;
      } else {
        dir = shared::refractDirection(dir, frame.n, 1.0f / m.ior);
        throughput *= m.base_color;
        in_glass = true, glass_ior = m.ior, through_glass = true;
      }
      origin = p;
      last_delta = true;
      continue;
    }
    if (hasSmoothLobe(m)) {
      rec.smoothVertex();
      nee_reaches = true, through_glass = false;
      if (kSun && world.sun.present) {
        radiance +=
            throughput * detail::sampleSun(world, m, frame, v_local, p, key, bounce, stats, rec);
      }
      if (kEmitters && !world.emitters.empty()) {
        radiance += throughput *
                    detail::sampleEmitters(world, m, frame, v_local, p, key, bounce, stats, rec);
      }
    }
    if (k - glass_events >= 4) {
      float q = std::min(0.95f, std::max(throughput.x, std::max(throughput.y, throughput.z)));
      if (!(shared::randomUniform(key, bounce, shared::kDimRoulette) < q)) break;
      throughput /= q;
    }
    BsdfSample s = sampleBsdf(m, v_local, shared::randomUniform(key, bounce, shared::kDimBsdf0),
                              shared::randomUniform(key, bounce, shared::kDimBsdf1),
                              shared::randomUniform(key, bounce, shared::kDimLobe));
    if (!s.valid || s.l.z <= 0.0f) break;
    throughput *= s.weight;
    if (throughput == glm::vec3(0.0f)) break;
    if (s.delta) nee_reaches = false;
    last_delta = s.delta;
    last_pdf = s.pdf;
    any_smooth = any_smooth || !s.delta;
    origin = p;
    dir = glm::normalize(frame.toWorld(s.l));
  }
  return radiance;
}

}  // namespace rdm
