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
#include "shared/rdm_sobol.h"
#include "shared/rdm_walk.h"
#include "shared/rdm_gpu_layout.h"

layout(local_size_x = kWorkgroupSize) in;

// The scene's effect set: a scene without sun or emitters runs a kernel without that code.
layout(constant_id = 0) const bool kSun = true;
layout(constant_id = 1) const bool kEmitters = true;
// Slot-set recording (docs/spec.md section 8): off, the recording code is compiled out.
layout(constant_id = 2) const bool kRecord = false;

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
layout(std430, set = 0, binding = kBindingSlotSets) buffer SlotSetsBuffer { uint slot_sets[]; };
layout(std430, set = 0, binding = kBindingSlotEmitters) readonly buffer SlotEmittersBuffer { uint slot_first[]; };
layout(push_constant) uniform PushBlock { GpuPush push; };

const int kWalkContinue = 0;
const int kWalkHit = 1;
const int kWalkMiss = 2;
const int kWalkBoundExceeded = 3;  // a bug: every walk leaves the grid within the bound

// Loop iterations this invocation's SIMD vector has run in this dispatch (see main).
uint g_iters = 0u;

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
float s_local_sum;  // a face-light job's local emitter CDF mass (data.w; docs/spec.md 3.2)
ivec3 g_slot;       // the slot of the path's job

// ---- Slot sets (kRecord) -----------------------------------------------------------------
// The slots this path's walks enter, into its RDM's bitsets (rdm_gpu_layout.h): atomics into
// a global buffer, so a path suspended and resumed keeps what it recorded.
uint g_set_base = 0u;   // first word of the RDM's sets
uint g_set_words = 0u;  // W: words per bitset
int g_last_slot = -1;   // the slot recorded last (a repeat needs no atomic)
bool g_first_segment;   // the walk in progress is the path's first segment
bool g_smooth_recorded = false;

void recordSlot(int slot_index) {
  if (slot_index == g_last_slot) return;
  g_last_slot = slot_index;
  const uint word = uint(slot_index) >> 5;
  const uint bit = 1u << (uint(slot_index) & 31u);
  atomicOr(slot_sets[g_set_base + word], bit);
  if (g_first_segment) atomicOr(slot_sets[g_set_base + g_set_words + word], bit);
}

void recordSmoothVertex() {
  if (g_smooth_recorded) return;
  g_smooth_recorded = true;
  atomicOr(slot_sets[g_set_base + 2u * g_set_words], 1u);
}

// ---- Voxel walk (shared/rdm_walk.h), resumable ------------------------------------------
ShWalk g_walk;
int g_step;
ivec3 g_extent;
bool g_regular;          // walkRegular(g_walk): brick steps allowed
int g_open_brick = -1;   // block * 64 + brick of the last brick found non-empty
uint g_brick_words = 0u; // index of the first brick mask word (set in main)

// Sets up a walk of the ray (o, d); false when the ray misses the grid.
bool startWalk(vec3 o, vec3 d) {
  g_step = 0;
  bool inside = walkStart(g_walk, o, d, g_extent);
  g_regular = walkRegular(g_walk);
  return inside;
}
// Axis crossed to enter the hit voxel: the first of the crossed axes with the largest |d|.
int hitAxis() {
  if (g_step == 0 && g_walk.mask == 0) return -1;  // the start cell is solid
  return entryAxis(g_walk.mask, g_walk.d);
}

uint voxelPalette(int block, ivec3 local) {
  uint index = uint(block) * uint(kBlockVoxelCount) + uint(local.x + 16 * local.y + 256 * local.z);
  return (voxels[index >> 2] >> ((index & 3u) * 8u)) & 0xffu;
}

// VoxelWorld::occupancy: two words per block after the blocks' voxel words (vulkan_bake.cpp).
// The cube the walk leaves from the current cell of `block` (walkBlockStepBits). A brick found
// non-empty is remembered, so the walk reads the mask once per brick.
int cellStepBits(int block) {
  int brick = walkBrickIndex(g_walk.cell & 15), key = block * 64 + brick;
  if (key == g_open_brick) return kWalkVoxelBits;
  uint word = voxels[g_brick_words + 2u * uint(block) + uint(brick >> 5)];
  if (((word >> uint(brick & 31)) & 1u) != 0u) g_open_brick = key;
  return walkBlockStepBits(word, brick, g_regular);
}

// One step of the walk; on kWalkHit `palette` receives the hit voxel's palette index.
int walkStep(out uint palette) {
  palette = 0u;
  if (g_step >= params.world.w) return kWalkBoundExceeded;
  ivec3 slot = g_walk.cell >> 4;
  int slot_index = slot.x + params.world.x * (slot.y + params.world.y * slot.z);
  if (kRecord) recordSlot(slot_index);
  int block = slots[slot_index];
  int bits = block < 0 ? kWalkSlotBits : cellStepBits(block);
  if (bits == kWalkVoxelBits) {
    palette = voxelPalette(block, g_walk.cell & 15);
    if (palette != 0u) return kWalkHit;
  }
  walkLeave(g_walk, bits);
  if (g_walk.mask == 0) return kWalkMiss;
  if (any(lessThan(g_walk.cell, ivec3(0))) || any(greaterThanEqual(g_walk.cell, g_extent))) return kWalkMiss;
  ++g_step;
  return kWalkContinue;
}

BsdfMaterial materialOf(uint palette) {
  BsdfMaterial m;
  m.base_color = materials[palette].base_metallic.xyz;
  m.metallic = materials[palette].base_metallic.w;
  m.f0 = materials[palette].f0_alpha.xyz;
  m.alpha = materials[palette].f0_alpha.w;
  return m;
}

#include "bake_emitter_choice.glsl"

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
      // An RDM's first segment adds no direct sun (docs/spec.md section 3); a camera's does.
      float w = s_k == 1u ? ((s_flags & kFlagCamera) != 0u ? 1.0f : 0.0f)
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
  const vec3 p = entryPoint(g_walk.o, g_walk.d, g_walk.t, g_walk.cell, axis);
  const int face = entryFace(axis, s_dir[axis]);
  const ShFrame frame = faceFrameOf(face);
  const vec3 v_local = frameToLocal(frame, -s_dir);
  if (materials[palette].flags.x != 0u) {
    float w = 1.0f;
    if (kEmitters && (s_k > 1u || (s_flags & kFlagFirstWeighted) != 0u) && (s_flags & kFlagLastDelta) == 0u) {
      float pdf_e = emitterPdf(materials[palette].emission.xyz, g_walk.t * g_walk.t, v_local.z);
      if (s_k == 1u) pdf_e *= faceLightPickFactor(s_local_sum, slotsAdjacent(g_walk.cell >> 4, g_slot));
      w = misPowerHeuristic(s_last_pdf, pdf_e);
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
  if (kRecord) recordSmoothVertex();
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

// Emitter next-event estimation at a face-light path's origin (docs/spec.md section 3.2), with
// bounce 0's draws (integrator.cpp sampleEmittersAtFace); the segment starts after its verdict.
void startFaceEmitterSampling() {
  const vec3 n = vec3(faceNormal(s_face));
  const int index = pickFaceLightEmitter(s_local_sum, randomUniform(s_key, 0u, kDimEmitterChoice));
  g_searched = 27u + 32u;
  const ivec4 voxel_face = emitters[index].voxel_face;
  const vec3 radiance = emitters[index].radiance.xyz;
  const vec3 q = emitterFacePoint(voxel_face.xyz, voxel_face.w, randomUniform(s_key, 0u, kDimEmitterPoint0),
                                  randomUniform(s_key, 0u, kDimEmitterPoint1));
  vec3 to = q - s_origin;
  float dist2 = dot(to, to);
  vec3 l = to / sqrt(dist2);
  float cos_l = dot(n, l);
  float cos_e = -dot(vec3(faceNormal(voxel_face.w)), l);
  if (!(dist2 > 0.0f) || cos_l <= 0.0f || cos_e <= 0.0f) {
    startSegment();
    return;
  }
  ++s_rays;
  const float pick = faceLightPickFactor(s_local_sum, slotsAdjacent(voxel_face.xyz >> 4, g_slot));
  s_pending = faceLightEmitterSample(radiance, cos_l, emitterPdf(radiance, dist2, cos_e) * pick);
  s_target = voxel_face.xyz;
  s_target_axis = voxel_face.w / 2;
  s_vertex = s_origin;
  s_shadow_dir = l;
  if (startWalk(s_origin, l)) {
    s_phase = kPhaseFaceEmitterShadow;
  } else {
    startSegment();
  }
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

// A camera job's path (docs/spec.md section 4): through pixel job.z jittered over the pixel,
// as rdm::renderReference draws it.
void initCameraPath(uint pixel) {
  const uint width = uint(params.camera.origin.w);
  const float px = float(pixel % width) + randomUniform(s_key, 0u, kDimOrigin0);
  const float py = float(pixel / width) + randomUniform(s_key, 0u, kDimOrigin1);
  const float a = 2.0f * px / params.camera.origin.w - 1.0f;
  const float b = 1.0f - 2.0f * py / params.camera.forward.w;
  s_origin = params.camera.origin.xyz;
  s_dir = normalize(params.camera.forward.xyz + a * params.camera.right.xyz + b * params.camera.up.xyz);
  s_throughput = vec3(1.0f);
  s_radiance = vec3(0.0f);
  s_k = 1u;
  s_flags = kFlagCamera;
  s_last_pdf = 0.0f;
  s_weight = 1.0f;
  startSegment();
}

// Draws the origin direction of the path (docs/spec.md section 3): level 0 jitter over the texel,
// levels 1-6 the prefilter lobe, level 7 cosine-distributed over the face's hemisphere; a
// face-light job (kFaceLightLevel, section 3.2) cosine-distributed from a point on its voxel face.
void initPath(uvec4 job, uint sample_index) {
  const uint slot_key = job.x;
  const int level = int(job.y & 15u);
  if (uint(level) == kJobCameraLevel) {
    initCameraPath(job.z);
    return;
  }
  const int face = int((job.y >> 4) & 15u);
  const int S = int((job.y >> 8) & kJobSizeMask);
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
  if (uint(level) == kFaceLightLevel) {  // a face-light path: from a point on one voxel face
    const int voxel_index = int(job.z & 0xffffu) / kFaceCount;
    const ivec3 voxel = slot * 16 + ivec3(voxel_index & 15, (voxel_index >> 4) & 15, voxel_index >> 8);
    const vec2 p = owenSobolPoint(sample_index, pathKey(params.config.x, slot_key, kFaceLightLevel, job.z & 0xffffu, 0u));
    const OriginDraw o = originCosineDraw(frame, p.x, p.y);
    s_origin = faceLightOrigin(voxel, face, randomUniform(s_key, 0u, kDimFacePoint0), randomUniform(s_key, 0u, kDimFacePoint1));
    s_weight = o.weight;
    s_dir = o.dir;
    s_face = face;
    s_last_pdf = faceLightDirectionPdf(dot(frame.n, o.dir));
    s_flags = kFlagFirstWeighted;
    if (!o.traced) {
      finishPath();
    } else if (kEmitters && params.config.z != 0u) {
      s_phase = kPhaseFaceEmitterStart;  // in the main loop, which counts the emitter search
    } else {
      startSegment();
    }
    return;
  }
  float u0 = randomUniform(s_key, 0u, kDimOrigin0);
  float u1 = randomUniform(s_key, 0u, kDimOrigin1);
  if ((job.y & kJobFootprintSobol) != 0u) {  // stratified over the footprint, keyed by sample 0
    const uint texel = uint(face * S * S + j * S + i);
    const vec2 p = owenSobolPoint(sample_index, pathKey(params.config.x, slot_key, 0u, texel, 0u));
    u0 = p.x;
    u1 = p.y;
  }
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
  g_walk.t = st.throughput.w;
  s_radiance = st.radiance.xyz;
  s_vertex = st.vertex.xyz;
  s_shadow_dir = st.shadow_dir.xyz;
  s_pending = st.pending.xyz;
  g_walk.cell = st.cell.xyz;
  g_walk.mask = st.cell.w;
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
    g_walk.o = s_origin;
    g_walk.d = s_dir;
  } else {
    g_walk.o = s_vertex;
    g_walk.d = s_shadow_dir;
  }
  g_walk.inv = vec3(1.0f) / g_walk.d;
  g_regular = walkRegular(g_walk);
}

void savePath(uint id) {
  GpuPathState st;
  st.origin = vec4(s_origin, s_last_pdf);
  st.dir = vec4(s_dir, s_weight);
  st.throughput = vec4(s_throughput, g_walk.t);
  st.radiance = vec4(s_radiance, 0.0f);
  st.vertex = vec4(s_vertex, 0.0f);
  st.shadow_dir = vec4(s_shadow_dir, 0.0f);
  st.pending = vec4(s_pending, 0.0f);
  st.cell = ivec4(g_walk.cell, g_walk.mask);
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
  const uint S = (job.y >> 8) & kJobSizeMask;
  const bool camera = level == kJobCameraLevel;  // keyed (camera, 0, pixel, sample)
  const uint texel = camera ? job.z : face * S * S + (job.z >> 16) * S + (job.z & 0xffffu);
  s_key = pathKey(params.config.x, job.x, camera ? 0u : level, texel, sample_index);
  g_slot = ivec3(int(job.x & 0xffu), int((job.x >> 8) & 0xffu), int(job.x >> 16));
  s_local_sum = level == kFaceLightLevel ? uintBitsToFloat(job.w) : 0.0f;
  g_extent = params.world.xyz * kBlockSize;
  g_brick_words = uint(voxels.length()) / uint(kBlockVoxelCount / 4 + 2) * uint(kBlockVoxelCount / 4);
  if (kRecord) {
    g_set_words = (uint(params.world.x * params.world.y * params.world.z) + 31u) / 32u;
    g_set_base = job.w * (2u * g_set_words + 1u);
  }

  // Initialise the walk state so a path saved outside a walk stores defined values.
  g_walk.o = vec3(0.0f);
  g_walk.d = vec3(0.0f);
  g_walk.inv = vec3(0.0f);
  g_walk.cell = ivec3(0);
  g_walk.mask = 0;
  g_walk.t = 0.0f;
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
    if (s_phase == kPhaseSegment || s_phase == kPhaseSunShadow || s_phase == kPhaseEmitterShadow ||
        s_phase == kPhaseFaceEmitterShadow) {
      uint palette = 0u;
      int r = kWalkContinue;
      g_first_segment = s_phase == kPhaseSegment && s_k == 1u;
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
      } else if (s_phase == kPhaseFaceEmitterShadow) {
        if (r == kWalkHit && hitAxis() == s_target_axis && g_walk.cell == s_target) s_radiance += s_pending;
        startSegment();
      } else {
        if (r == kWalkHit && hitAxis() == s_target_axis && g_walk.cell == s_target) s_radiance += s_throughput * s_pending;
        s_phase = kPhaseContinue;
      }
    } else if (s_phase == kPhaseEmitterStart) {
      startEmitterSampling();
    } else if (s_phase == kPhaseFaceEmitterStart) {
      startFaceEmitterSampling();
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
