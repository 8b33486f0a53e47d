// RDM bake kernel (docs/spec.md sections 3 and 5): one invocation advances one path, (texel job,
// sample) of the current batch, as a resumable state machine. lavapipe stops every loop
// after 65,535 back-edges per invocation (docs/spec.md section 9), so the invocation counts every
// loop iteration it runs and, before the count could pass the budget, saves the whole path
// state (including a voxel walk in progress) and stops; the host dispatches again until no
// path is active. A resumed path computes exactly what an uninterrupted one would.
//
// The operations mirror rdm::tracePath (integrator.h) and rdm::traceVoxels (traversal.h);
// every convention (face frames, hemi-oct, hash, dims, BSDF) comes from shared/rdm_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared/rdm_shared.h"
#include "shared/rdm_gpu_layout.h"

layout(local_size_x = kWorkgroupSize) in;

// The scene's effect set: a scene without sun or emitters runs a kernel without that code.
layout(constant_id = 0) const bool kSun = true;
layout(constant_id = 1) const bool kEmitters = true;

layout(std430, set = 0, binding = kBindingParams) readonly buffer ParamsBuffer { GpuParams params; };
layout(std430, set = 0, binding = kBindingSlots) readonly buffer SlotsBuffer { int slots[]; };
layout(std430, set = 0, binding = kBindingVoxels) readonly buffer VoxelsBuffer { uint voxels[]; };
layout(std430, set = 0, binding = kBindingMaterials) readonly buffer MaterialsBuffer { GpuMaterial materials[]; };
layout(std430, set = 0, binding = kBindingEmitters) readonly buffer EmittersBuffer { GpuEmitter emitters[]; };
layout(std430, set = 0, binding = kBindingEmitterCdf) readonly buffer CdfBuffer { float emitter_cdf[]; };
layout(std430, set = 0, binding = kBindingJobs) readonly buffer JobsBuffer { GpuJob jobs[]; };
layout(std430, set = 0, binding = kBindingPaths) buffer PathsBuffer { GpuPathState paths[]; };
layout(std430, set = 0, binding = kBindingResults) writeonly buffer ResultsBuffer { vec4 results[]; };
layout(std430, set = 0, binding = kBindingCounters) buffer CountersBuffer { GpuCounters counters; };
layout(push_constant) uniform PushBlock { GpuPush push; };

const int kWalkContinue = 0;
const int kWalkHit = 1;
const int kWalkMiss = 2;
const int kWalkBoundExceeded = 3;  // a bug: every walk leaves the grid within the bound

// Loop iterations this invocation's SIMD vector has run in this dispatch (see main).
uint g_iters = 0u;

// ---- Two-level voxel walk (rdm::traceVoxels with FloatRay), resumable ---------------------
vec3 g_o;
vec3 g_d;
vec3 g_inv;
ivec3 g_cell;
int g_mask;
float g_t;
int g_step;
ivec3 g_extent;
bool g_regular;          // rayRegular() of the ray being walked: brick steps allowed
int g_open_brick = -1;   // block * 64 + brick of the last brick found non-empty

bool rayMoving(int a) { return g_d[a] != 0.0f; }
bool rayPositive(int a) { return g_d[a] > 0.0f; }
float boundaryTime(int a, int plane) { return (float(plane) - g_o[a]) * g_inv[a]; }
int startCell(int a) {
  float p = g_o[a];
  return !rayMoving(a) || rayPositive(a) ? int(floor(p)) : int(ceil(p)) - 1;
}
// FloatRay::cellAt: the cell on a non-crossing axis at time t, consistent with the
// boundary-time ties, clamped to [lo, hi]. The CPU's fix-up loops move floor(p) by at most
// one cell (p's rounding error is far below a voxel in a 4096-voxel grid); they are written
// here as two unrolled steps each, so the walk has no loop besides the kernel's own.
bool cellUp(int a, int c, int hi, float t) { return c < hi && boundaryTime(a, c + 1) <= t; }
bool cellDown(int a, int c, int lo, float t) { return c > lo && boundaryTime(a, c) > t; }
int cellAt(int a, float t, int lo, int hi) {
  float p = g_o[a] + t * g_d[a];
  int c = rayPositive(a) ? int(floor(p)) : int(ceil(p)) - 1;
  c = clamp(c, lo, hi);
  if (rayPositive(a)) {
    if (cellUp(a, c, hi, t)) ++c;
    if (cellUp(a, c, hi, t)) ++c;
    if (cellDown(a, c, lo, t)) --c;
    if (cellDown(a, c, lo, t)) --c;
  } else {
    if (c > lo && boundaryTime(a, c) <= t) --c;
    if (c > lo && boundaryTime(a, c) <= t) --c;
    if (c < hi && boundaryTime(a, c + 1) > t) ++c;
    if (c < hi && boundaryTime(a, c + 1) > t) ++c;
  }
  return c;
}

// FloatRay::regular: every boundary time finite and strictly increasing along the ray, so a
// brick step lands where voxel steps would (traversal.h); other rays walk voxel by voxel.
// The axis loops here are written out: lavapipe counts every back-edge against the
// invocation's loop budget (docs/spec.md section 9).
bool axisRegular(int a) {
  return abs(g_o[a]) <= 1048576.0f &&
         (!rayMoving(a) || (abs(g_inv[a]) <= 1e20f && abs(g_inv[a]) >= 1e-20f));
}
bool rayRegular() { return axisRegular(0) && axisRegular(1) && axisRegular(2); }

bool startAxisBounds(int a, inout float t_enter, inout float t_exit, inout bool entering, inout bool has_exit,
                     inout int mask) {
  if (!rayMoving(a)) {
    int c = startCell(a);
    return c >= 0 && c < g_extent[a];
  }
  float t_near = boundaryTime(a, rayPositive(a) ? 0 : g_extent[a]);
  float t_far = boundaryTime(a, rayPositive(a) ? g_extent[a] : 0);
  if (t_enter < t_near) {
    t_enter = t_near;
    mask = 1 << a;
    entering = true;
  } else if (entering && t_enter == t_near) {
    mask |= 1 << a;
  }
  if (!has_exit || t_far < t_exit) {
    t_exit = t_far;
    has_exit = true;
  }
  return true;
}

bool startAxisCell(int a, float t_enter, bool entering, int mask) {
  if ((mask & (1 << a)) != 0) {
    g_cell[a] = rayPositive(a) ? 0 : g_extent[a] - 1;
  } else if (entering && rayMoving(a)) {
    g_cell[a] = cellAt(a, t_enter, 0, g_extent[a] - 1);
  } else {
    g_cell[a] = startCell(a);
    if (g_cell[a] < 0 || g_cell[a] >= g_extent[a]) return false;
  }
  return true;
}

// Sets up a walk of the ray (o, d); false when the ray misses the grid.
bool startWalk(vec3 o, vec3 d) {
  g_o = o;
  g_d = d;
  g_inv = vec3(1.0f) / d;
  g_regular = rayRegular();
  g_step = 0;
  float t_enter = 0.0f;
  float t_exit = 0.0f;
  bool entering = false;
  bool has_exit = false;
  int mask = 0;
  if (!startAxisBounds(0, t_enter, t_exit, entering, has_exit, mask)) return false;
  if (!startAxisBounds(1, t_enter, t_exit, entering, has_exit, mask)) return false;
  if (!startAxisBounds(2, t_enter, t_exit, entering, has_exit, mask)) return false;
  if (has_exit && !(t_enter < t_exit)) return false;
  g_t = t_enter;
  g_mask = mask;
  if (!startAxisCell(0, t_enter, entering, mask)) return false;
  if (!startAxisCell(1, t_enter, entering, mask)) return false;
  if (!startAxisCell(2, t_enter, entering, mask)) return false;
  return true;
}

void crossingAxis(int a, ivec3 planes, inout int mask) {
  if (!rayMoving(a)) return;
  float t = boundaryTime(a, planes[a]);
  if (mask == 0 || t < g_t) {
    g_t = t;
    mask = 1 << a;
  } else if (t == g_t) {
    mask |= 1 << a;
  }
}
int nextCrossing(ivec3 planes) {
  int mask = 0;
  crossingAxis(0, planes, mask);
  crossingAxis(1, planes, mask);
  crossingAxis(2, planes, mask);
  return mask;
}
// Axis crossed to enter the hit voxel: the first of the crossed axes with the largest |d|.
int hitAxis() {
  if (g_step == 0 && g_mask == 0) return -1;  // the start cell is solid
  return entryAxis(g_mask, g_d);
}
void slotAxisCell(int a, ivec3 slot, ivec3 planes) {
  if ((g_mask & (1 << a)) != 0) {
    g_cell[a] = rayPositive(a) ? planes[a] : planes[a] - 1;
  } else if (rayMoving(a)) {
    g_cell[a] = cellAt(a, g_t, slot[a] * 16, slot[a] * 16 + 15);
  }
}

uint voxelPalette(int block, ivec3 local) {
  uint index = uint(block) * uint(kBlockVoxelCount) + uint(local.x + 16 * local.y + 256 * local.z);
  return (voxels[index >> 2] >> ((index & 3u) * 8u)) & 0xffu;
}

// Whether the 4^3 brick holding `local` has no solid voxel: VoxelWorld::occupancy's mask,
// two words per block after the blocks' voxel words (bake_vulkan.cpp).
uint g_brick_words = 0u;  // index of the first brick mask word (set in main)
int brickOf(ivec3 local) { return (local.x >> 2) | (local.y >> 2) << 2 | (local.z >> 2) << 4; }
bool brickEmpty(int block, int brick) {
  uint word = voxels[g_brick_words + 2u * uint(block) + uint(brick >> 5)];
  return ((word >> uint(brick & 31)) & 1u) == 0u;
}
// Whether the walk crosses the current cell's brick in one step: a regular ray in an empty
// brick. A brick found non-empty is remembered, so the walk reads the mask once per brick.
bool brickStep(int block) {
  int brick = brickOf(g_cell & 15), key = block * 64 + brick;
  if (key == g_open_brick) return false;
  if (!brickEmpty(block, brick)) {
    g_open_brick = key;
    return false;
  }
  return g_regular;
}

// rdm::detail::brickSkip: leaves the current empty 4^3 brick where voxel steps would. The
// axes reaching the brick's exit time first cross it; every other moving axis catches up by
// voxel steps (at most 3) to its cell at that time and joins the mask if it crosses a voxel
// plane exactly then.
float brickExitTime(int a) {
  return rayMoving(a) ? boundaryTime(a, (g_cell[a] & ~3) + (rayPositive(a) ? 4 : 0))
                      : uintBitsToFloat(0x7f800000u);  // +inf: a still axis never crosses
}
void brickCross(int a, int exit_mask) {
  if ((exit_mask & (1 << a)) != 0) g_cell[a] = (g_cell[a] & ~3) + (rayPositive(a) ? 4 : -1);
}
// One voxel step of axis a towards t_exit, while its next plane is not later than t_exit.
void catchUpStep(int a, int off, float t_exit, inout float tn, inout bool done, inout int mask) {
  if (done || t_exit < tn) {
    done = true;
    return;
  }
  if (t_exit == tn) mask |= 1 << a;
  g_cell[a] += off != 0 ? 1 : -1;
  tn = boundaryTime(a, g_cell[a] + off);
}
void brickCatchUp(int a, int exit_mask, float t_exit, inout int mask) {
  if (!rayMoving(a) || (exit_mask & (1 << a)) != 0) return;
  int off = rayPositive(a) ? 1 : 0;
  float tn = boundaryTime(a, g_cell[a] + off);
  bool done = false;
  catchUpStep(a, off, t_exit, tn, done, mask);
  catchUpStep(a, off, t_exit, tn, done, mask);
  catchUpStep(a, off, t_exit, tn, done, mask);
}
void brickSkip() {
  vec3 tb = vec3(brickExitTime(0), brickExitTime(1), brickExitTime(2));
  float t_exit = min(min(tb.x, tb.y), tb.z);
  int exit_mask = int(tb.x == t_exit) | int(tb.y == t_exit) << 1 | int(tb.z == t_exit) << 2;
  int mask = exit_mask;
  brickCross(0, exit_mask);
  brickCross(1, exit_mask);
  brickCross(2, exit_mask);
  brickCatchUp(0, exit_mask, t_exit, mask);
  brickCatchUp(1, exit_mask, t_exit, mask);
  brickCatchUp(2, exit_mask, t_exit, mask);
  g_t = t_exit;
  g_mask = mask;
}

// One step of the walk; on kWalkHit `palette` receives the hit voxel's palette index.
int walkStep(out uint palette) {
  palette = 0u;
  if (g_step >= params.world.w) return kWalkBoundExceeded;
  ivec3 slot = g_cell >> 4;
  int slot_index = slot.x + params.world.x * (slot.y + params.world.y * slot.z);
  int block = slots[slot_index];
  ivec3 positive = ivec3(greaterThan(g_d, vec3(0.0f)));
  if (block >= 0 && brickStep(block)) {
    brickSkip();
  } else if (block >= 0) {
    palette = voxelPalette(block, g_cell & 15);
    if (palette != 0u) return kWalkHit;
    g_mask = nextCrossing(g_cell + positive);
    ivec3 crossed = ivec3(g_mask & 1, (g_mask >> 1) & 1, (g_mask >> 2) & 1);
    g_cell += crossed * (positive * 2 - 1);
  } else {
    ivec3 planes = (slot + positive) * 16;
    g_mask = nextCrossing(planes);
    slotAxisCell(0, slot, planes);
    slotAxisCell(1, slot, planes);
    slotAxisCell(2, slot, planes);
  }
  if (g_mask == 0) return kWalkMiss;
  if (any(lessThan(g_cell, ivec3(0))) || any(greaterThanEqual(g_cell, g_extent))) return kWalkMiss;
  ++g_step;
  return kWalkContinue;
}

// ---- Path state ------------------------------------------------------------------------
uint s_phase;
uint s_k;
uint s_flags;
int s_face;
uint s_palette;
vec3 s_origin;
vec3 s_dir;
float s_last_pdf;
float s_weight;
vec3 s_throughput;
vec3 s_radiance;
vec3 s_vertex;
vec3 s_shadow_dir;
vec3 s_pending;
ivec3 s_target;
int s_target_axis;
uint s_key;
uint s_rays = 0u;

BsdfMaterial materialOf(uint palette) {
  BsdfMaterial m;
  m.base_color = materials[palette].base_metallic.xyz;
  m.metallic = materials[palette].base_metallic.w;
  m.f0 = materials[palette].f0_alpha.xyz;
  m.alpha = materials[palette].f0_alpha.w;
  return m;
}

float emitterPdf(vec3 radiance, float dist2, float cos_e) {
  return emitterSolidAnglePdf(params.sky_zenith.w, radiance, dist2, cos_e);  // w: total luminance
}

// EmitterList::pick: the first index whose cdf exceeds u (upper bound), clamped. A fixed
// 32-step search (enough for any count) so every lane runs the same iterations.
uint g_searched = 0u;
int pickEmitter(float u) {
  int count = int(params.config.z);
  int lo = 0;
  int hi = count;
  for (int n = 0; n < 32; ++n) {
    if (lo < hi) {
      int mid = lo + (hi - lo) / 2;
      if (emitter_cdf[mid] <= u) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
  }
  g_searched = 32u;
  return min(lo, count - 1);
}

void finishPath() { s_phase = kPhaseDone; }

// Starts the walk of path segment k from (s_origin, s_dir); a ray missing the grid is handled
// as an escape at once.
void missSegment();
void startSegment() {
  ++s_rays;
  s_phase = kPhaseSegment;
  if (!startWalk(s_origin, s_dir)) missSegment();
}

void missSegment() {
  s_radiance += s_throughput * skyGradient(params.sky_zenith.xyz, params.sky_horizon.xyz, params.sky_ground.xyz, s_dir);
  if (kSun && params.config.w != 0u) {
    vec3 e = s_dir - params.sun_direction.xyz;
    if (dot(e, e) <= params.sun_irradiance.w) {
      bool last_delta = (s_flags & kFlagLastDelta) != 0u;
      bool any_smooth = (s_flags & kFlagAnySmooth) != 0u;
      // An RDM's first segment adds no direct sun (docs/spec.md section 3).
      float w = s_k == 1u ? 0.0f
                          : (!last_delta ? misPowerHeuristic(s_last_pdf, params.sun_direction.w)
                                         : (any_smooth ? 0.0f : 1.0f));
      if (w > 0.0f) s_radiance += s_throughput * params.sun_radiance.xyz * w;
    }
  }
  finishPath();
}

void startEmitterSampling();
void startContinue() { s_phase = kPhaseContinue; }

void hitSegment(uint palette) {
  int axis = hitAxis();
  if (axis < 0) {
    finishPath();
    return;
  }
  const BsdfMaterial m = materialOf(palette);
  const vec3 p = entryPoint(g_o, g_d, g_t, g_cell, axis);
  const int face = entryFace(axis, s_dir[axis]);
  const ShFrame frame = faceFrameOf(face);
  const vec3 v_local = frameToLocal(frame, -s_dir);
  if (materials[palette].flags.x != 0u) {
    float w = 1.0f;
    if (kEmitters && s_k > 1u && (s_flags & kFlagLastDelta) == 0u) {
      w = misPowerHeuristic(s_last_pdf, emitterPdf(materials[palette].emission.xyz, g_t * g_t, v_local.z));
    }
    s_radiance += s_throughput * materials[palette].emission.xyz * w;
  }
  if (s_k > params.config.y) {
    finishPath();
    return;
  }
  s_vertex = p;
  s_face = face;
  s_palette = palette;
  if (!bsdfHasSmoothLobe(m)) {
    startContinue();
    return;
  }
  if (kSun && params.config.w != 0u) {
    vec3 l = frameToWorld(frameAroundDir(params.sun_direction.xyz),
                          sampleConeDir(params.sun_radiance.w, randomUniform(s_key, s_k, kDimSun0),
                                        randomUniform(s_key, s_k, kDimSun1)));
    vec3 l_local = frameToLocal(frame, l);
    if (l_local.z > 0.0f) {
      vec3 f = bsdfEval(m, v_local, l_local);
      if (f != vec3(0.0f)) {
        float w = misPowerHeuristic(params.sun_direction.w, bsdfPdf(m, v_local, l_local));
        s_pending = f * params.sun_irradiance.xyz * (l_local.z * w);
        s_shadow_dir = l;
        ++s_rays;
        if (!startWalk(p, l)) {
          s_radiance += s_throughput * s_pending;  // the shadow ray leaves the grid at once
        } else {
          s_phase = kPhaseSunShadow;
          return;
        }
      }
    }
  }
  s_phase = kPhaseEmitterStart;
}

void startEmitterSampling() {
  s_phase = kPhaseContinue;
  if (!kEmitters || params.config.z == 0u) return;
  const BsdfMaterial m = materialOf(s_palette);
  const ShFrame frame = faceFrameOf(s_face);
  const vec3 v_local = frameToLocal(frame, -s_dir);
  const int index = pickEmitter(randomUniform(s_key, s_k, kDimEmitterChoice));
  const ivec4 voxel_face = emitters[index].voxel_face;
  const vec3 radiance = emitters[index].radiance.xyz;
  const int axis = voxel_face.w / 2;
  const vec3 q = emitterFacePoint(voxel_face.xyz, voxel_face.w, randomUniform(s_key, s_k, kDimEmitterPoint0),
                                  randomUniform(s_key, s_k, kDimEmitterPoint1));
  vec3 to = q - s_vertex;
  float dist2 = dot(to, to);
  if (!(dist2 > 0.0f)) return;
  vec3 l = to / sqrt(dist2);
  vec3 l_local = frameToLocal(frame, l);
  float cos_e = -dot(vec3(faceNormal(voxel_face.w)), l);
  if (l_local.z <= 0.0f || cos_e <= 0.0f) return;
  vec3 f = bsdfEval(m, v_local, l_local);
  if (f == vec3(0.0f)) return;
  ++s_rays;
  float pdf_e = emitterPdf(radiance, dist2, cos_e);
  s_pending = vec3(0.0f);
  if (pdf_e > 0.0f && finiteFloat(pdf_e)) {
    float w = misPowerHeuristic(pdf_e, bsdfPdf(m, v_local, l_local));
    s_pending = f * radiance * (l_local.z * w / pdf_e);
  }
  s_target = voxel_face.xyz;
  s_target_axis = axis;
  s_shadow_dir = l;
  if (startWalk(s_vertex, l)) s_phase = kPhaseEmitterShadow;
}

void continuePath() {
  const BsdfMaterial m = materialOf(s_palette);
  const ShFrame frame = faceFrameOf(s_face);
  const vec3 v_local = frameToLocal(frame, -s_dir);
  if (s_k >= 4u) {
    float q = min(0.95f, max(s_throughput.x, max(s_throughput.y, s_throughput.z)));
    if (!(randomUniform(s_key, s_k, kDimRoulette) < q)) {
      finishPath();
      return;
    }
    s_throughput /= q;
  }
  BsdfDraw s = bsdfSample(m, v_local, randomUniform(s_key, s_k, kDimBsdf0), randomUniform(s_key, s_k, kDimBsdf1),
                          randomUniform(s_key, s_k, kDimLobe));
  if (!s.valid || s.l.z <= 0.0f) {
    finishPath();
    return;
  }
  s_throughput *= s.weight;
  if (s_throughput == vec3(0.0f)) {
    finishPath();
    return;
  }
  s_flags = (s.delta ? kFlagLastDelta : 0u) | (((s_flags & kFlagAnySmooth) != 0u || !s.delta) ? kFlagAnySmooth : 0u);
  s_last_pdf = s.pdf;
  s_origin = s_vertex;
  s_dir = normalize(frameToWorld(frame, s.l));
  ++s_k;
  startSegment();
}

// Draws the origin direction of the path (docs/spec.md section 3): level 0 jitter over the texel,
// levels 1-6 the prefilter lobe, level 7 cosine-distributed over the face's hemisphere.
void initPath(uvec4 job, uint sample_index) {
  const uint slot_key = job.x;
  const int level = int(job.y & 15u);
  const int face = int((job.y >> 4) & 15u);
  const int S = int(job.y >> 8);
  const int i = int(job.z & 0xffffu);
  const int j = int(job.z >> 16);
  const ShFrame frame = faceFrameOf(face);
  const ivec3 slot = ivec3(int(slot_key & 0xffu), int((slot_key >> 8) & 0xffu), int(slot_key >> 16));
  s_origin = vec3(slot * 16 + ivec3(8) + 8 * faceNormal(face));
  s_throughput = vec3(1.0f);
  s_radiance = vec3(0.0f);
  s_k = 1u;
  s_flags = 0u;
  s_last_pdf = 0.0f;
  const float u0 = randomUniform(s_key, 0u, kDimOrigin0);
  const float u1 = randomUniform(s_key, 0u, kDimOrigin1);
  OriginDraw o;
  if (level == kDiffuseLevel) {
    o = originCosineDraw(frame, u0, u1);
  } else if (level == 0) {
    o = originTexelDraw(frame, i, j, S, u0, u1);
  } else {
    const vec3 w = normalize(frameToWorld(frame, vec3(texelCentralDirection(i, j, S))));
    o = originLobeDraw(frame, w, roughnessAlpha(level), u0, u1);
  }
  s_weight = o.weight;
  if (!o.traced) {
    finishPath();
    return;
  }
  s_dir = o.dir;
  startSegment();
}

void loadPath(uint id) {
  GpuPathState st = paths[id];
  s_origin = st.origin.xyz;
  s_last_pdf = st.origin.w;
  s_dir = st.dir.xyz;
  s_weight = st.dir.w;
  s_throughput = st.throughput.xyz;
  g_t = st.throughput.w;
  s_radiance = st.radiance.xyz;
  s_vertex = st.vertex.xyz;
  s_shadow_dir = st.shadow_dir.xyz;
  s_pending = st.pending.xyz;
  g_cell = st.cell.xyz;
  g_mask = st.cell.w;
  s_target = st.target.xyz;
  s_target_axis = st.target.w;
  s_phase = st.control.x;
  s_k = st.control.y;
  s_flags = st.control.z & 0xffu;
  s_face = int((st.control.z >> 8) & 0xffu);
  s_palette = st.control.z >> 16;
  g_step = int(st.control.w);
  // The walk in progress: the segment ray or the shadow ray from the vertex.
  if (s_phase == kPhaseSegment) {
    g_o = s_origin;
    g_d = s_dir;
  } else {
    g_o = s_vertex;
    g_d = s_shadow_dir;
  }
  g_inv = vec3(1.0f) / g_d;
  g_regular = rayRegular();
}

void savePath(uint id) {
  GpuPathState st;
  st.origin = vec4(s_origin, s_last_pdf);
  st.dir = vec4(s_dir, s_weight);
  st.throughput = vec4(s_throughput, g_t);
  st.radiance = vec4(s_radiance, 0.0f);
  st.vertex = vec4(s_vertex, 0.0f);
  st.shadow_dir = vec4(s_shadow_dir, 0.0f);
  st.pending = vec4(s_pending, 0.0f);
  st.cell = ivec4(g_cell, g_mask);
  st.target = ivec4(s_target, s_target_axis);
  st.control = uvec4(s_phase, s_k, s_flags | (uint(s_face) << 8) | (s_palette << 16), uint(g_step));
  paths[id] = st;
}

void main() {
  const uint id = gl_GlobalInvocationID.x;
  const uint job_count = push.batch.x;
  const uint samples = push.batch.y;
  if (id >= job_count * samples) return;
  const uvec4 job = jobs[id / samples].data;
  const uint sample_index = push.batch.z + id % samples;
  const uint budget = min(push.batch.w, kMaxLoopBudget);
  const uint level = job.y & 15u;
  const uint face = (job.y >> 4) & 15u;
  const uint S = job.y >> 8;
  const uint texel = face * S * S + (job.z >> 16) * S + (job.z & 0xffffu);
  s_key = pathKey(params.config.x, job.x, level, texel, sample_index);
  g_extent = params.world.xyz * kBlockSize;
  g_brick_words = uint(voxels.length()) / uint(kBlockVoxelCount / 4 + 2) * uint(kBlockVoxelCount / 4);

  // Initialise the walk state so a path saved outside a walk stores defined values.
  g_o = vec3(0.0f);
  g_d = vec3(0.0f);
  g_inv = vec3(0.0f);
  g_cell = ivec3(0);
  g_mask = 0;
  g_t = 0.0f;
  g_step = 0;
  s_vertex = vec3(0.0f);
  s_shadow_dir = vec3(0.0f);
  s_pending = vec3(0.0f);
  s_target = ivec3(0);
  s_target_axis = -1;
  s_face = 0;
  s_palette = 0u;
  loadPath(id);
  if (s_phase == kPhaseDone) return;
  if (s_phase == kPhaseInit) initPath(job, sample_index);

  // The outer loop runs one event per iteration (a segment's hit or miss, a shadow ray's
  // verdict, a bounce); the inner loop only walks voxels, so on SIMD hardware lanes still
  // walking do not drag the event code through every voxel step.
  //
  // Loop accounting: lavapipe's limiter counts the back-edges a whole SIMD vector (= one
  // subgroup, 8 lanes) takes, i.e. an inner loop runs as long as its longest lane. So each
  // outer iteration adds the subgroup maximum of every loop's iterations, computed where all
  // lanes still in the loop take part, and a lane only leaves the loop after that
  // accounting: g_iters is then the vector's own count, identical on every lane.
  bool suspended = false;
  for (uint n = 0u; n < kMaxLoopBudget; ++n) {
    if (s_phase == kPhaseDone || suspended) break;
    if (g_iters + kStepReserve > budget) break;  // suspend: the next dispatch continues
    uint walked = 0u;
    g_searched = 0u;
    if (s_phase == kPhaseSegment || s_phase == kPhaseSunShadow || s_phase == kPhaseEmitterShadow) {
      uint palette = 0u;
      int r = kWalkContinue;
      for (uint m = 0u; m < kMaxLoopBudget; ++m) {
        if (g_iters + walked + kStepReserve > budget) break;
        ++walked;
        r = walkStep(palette);
        if (r != kWalkContinue) break;
      }
      if (r == kWalkBoundExceeded) {
        s_weight = kWeightWalkBoundExceeded;
        s_phase = kPhaseDone;
      } else if (r == kWalkContinue) {
        suspended = true;  // inside the walk; the state is saved below
      } else if (s_phase == kPhaseSegment) {
        if (r == kWalkHit) {
          hitSegment(palette);
        } else {
          missSegment();
        }
      } else if (s_phase == kPhaseSunShadow) {
        if (r == kWalkMiss) s_radiance += s_throughput * s_pending;
        s_phase = kPhaseEmitterStart;
      } else {
        if (r == kWalkHit && hitAxis() == s_target_axis && g_cell == s_target) s_radiance += s_throughput * s_pending;
        s_phase = kPhaseContinue;
      }
    } else if (s_phase == kPhaseEmitterStart) {
      startEmitterSampling();
    } else if (s_phase == kPhaseContinue) {
      continuePath();
    }
    g_iters += 1u + subgroupMax(walked) + subgroupMax(g_searched);
  }

  savePath(id);
  if (s_phase == kPhaseDone) {
    results[id] = vec4(s_radiance, s_weight);
  } else {
    atomicAdd(counters.values.x, 1u);
  }
  if (s_rays > 0u) {
    uint before = atomicAdd(counters.values.y, s_rays);
    if (before > 0xffffffffu - s_rays) atomicAdd(counters.values.z, 1u);
  }
}
