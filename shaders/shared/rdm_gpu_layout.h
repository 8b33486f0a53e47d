// GPU buffer layouts of the Vulkan bake (std430), shared by shaders/bake.comp and
// libs/vulkan/src/vulkan_bake.cpp. Every member is a 16-byte vector so std430 and C++ agree
// without padding rules; the C++ side static_asserts sizes and offsets.
#ifndef RDM_GPU_LAYOUT_H
#define RDM_GPU_LAYOUT_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
namespace rdm::gpu {
using namespace glm;
#define RDM_GPU_CONST constexpr
#else
#define RDM_GPU_CONST const
#endif

// Descriptor bindings of set 0.
RDM_GPU_CONST int kBindingParams = 0;     // GpuParams
RDM_GPU_CONST int kBindingSlots = 1;      // int per slot: oriented block index, -1 empty
RDM_GPU_CONST int kBindingVoxels = 2;     // uint per 4 voxels of each oriented block
RDM_GPU_CONST int kBindingMaterials = 3;  // GpuMaterial[256], by palette index
RDM_GPU_CONST int kBindingEmitters = 4;   // GpuEmitter[], (slot, voxel, face) order
RDM_GPU_CONST int kBindingEmitterCdf = 5; // float[], normalised, last = 1
RDM_GPU_CONST int kBindingJobs = 6;       // GpuJob[] of the current batch
RDM_GPU_CONST int kBindingPaths = 7;      // GpuPathState[] of the current batch
RDM_GPU_CONST int kBindingResults = 8;    // vec4[] per path: radiance xyz, sample weight w
RDM_GPU_CONST int kBindingCounters = 9;   // GpuCounters
// Slot sets of the batch's RDMs (recording kernels only; a 16-byte stub otherwise): per
// batch-local RDM r (GpuJob data.w), 2W + 1 words from word r (2W + 1): W words of full-set
// bits, W of first-set bits (bit s % 32 of word s / 32 for linear slot index s), then a word
// that is non-zero when some path met a non-delta vertex; W = ceil(slot count / 32).
RDM_GPU_CONST int kBindingSlotSets = 10;
RDM_GPU_CONST int kBindingSlotEmitters = 11;  // EmitterList::slot_first (uint per slot + 1)
RDM_GPU_CONST int kBindingCount = 12;

RDM_GPU_CONST int kWorkgroupSize = 64;
// lavapipe stops every loop after 65,535 back-edges (docs/spec.md section 9), counted per SIMD
// vector (one subgroup); an invocation suspends its path once its subgroup has run this many
// loop iterations in the dispatch.
RDM_GPU_CONST uint kMaxLoopBudget = 60000u;
// Iterations one event of the kernel may add besides voxel steps (the outer loop's own and
// the emitter search's 32); the budget check keeps this in reserve.
RDM_GPU_CONST uint kStepReserve = 128u;

// Path phases (GpuPathState.control.x).
RDM_GPU_CONST uint kPhaseInit = 0u;          // origin direction not drawn yet
RDM_GPU_CONST uint kPhaseSegment = 1u;       // walking the path segment of bounce k
RDM_GPU_CONST uint kPhaseSunShadow = 2u;     // walking the sun shadow ray at x_k
RDM_GPU_CONST uint kPhaseEmitterStart = 3u;  // emitter next-event estimation at x_k
RDM_GPU_CONST uint kPhaseEmitterShadow = 4u; // walking the emitter shadow ray at x_k
RDM_GPU_CONST uint kPhaseContinue = 5u;      // roulette and BSDF sampling at x_k
RDM_GPU_CONST uint kPhaseDone = 6u;
RDM_GPU_CONST uint kPhaseFaceEmitterStart = 7u;   // a face-light path's emitter NEE at its origin
RDM_GPU_CONST uint kPhaseFaceEmitterShadow = 8u;  // walking that shadow ray

// The result weight of a path whose voxel walk ran past its loop bound (the grid's extent in
// steps). Real weights are >= 0; the host treats this one as a bug (RDM_CHECK), never a miss.
RDM_GPU_CONST float kWeightWalkBoundExceeded = -1.0f;

// Path flags (GpuPathState.control.z, low byte).
RDM_GPU_CONST uint kFlagLastDelta = 1u;
RDM_GPU_CONST uint kFlagAnySmooth = 2u;
RDM_GPU_CONST uint kFlagFirstWeighted = 4u;  // emitters the first segment hits are MIS-weighted
RDM_GPU_CONST uint kFlagCamera = 8u;  // a camera path: the sun its first segment sees counts fully

// A camera job (rdm render --backend vulkan; docs/spec.md section 4): level kJobCameraLevel,
// data.x the camera index and data.z the pixel y * width + x, which the path key reads as
// (camera, level 0, pixel, sample) like rdm::renderReference's.
RDM_GPU_CONST uint kJobCameraLevel = 9u;

// The camera of a render's jobs (zero in bakes): the position in voxel units and the basis of
// rdm::cameraRayDirection with right and up scaled to the image plane at distance 1, so the
// ray through pixel position (px, py) is forward + (2 px / width - 1) right +
// (1 - 2 py / height) up.
struct GpuCamera {
  vec4 origin;   // xyz voxel units, w image width
  vec4 forward;  // xyz unit, w image height
  vec4 right;    // xyz, tan(fov / 2) * width / height long
  vec4 up;       // xyz, tan(fov / 2) long
};

struct GpuParams {
  ivec4 world;           // slots x, y, z; voxel-walk step bound
  uvec4 config;          // seed, max_bounces, emitter count, sun present
  vec4 sun_direction;    // xyz unit towards the sun, w pdf = 1 / omega
  vec4 sun_radiance;     // xyz irradiance / omega, w 1 - cos(theta)
  vec4 sun_irradiance;   // xyz, w 4 sin^2(theta / 2)
  vec4 sky_zenith;       // xyz, w emitter total luminance
  vec4 sky_horizon;      // xyz
  vec4 sky_ground;       // xyz
  GpuCamera camera;
};

struct GpuMaterial {
  vec4 base_metallic;  // linear base colour, metallic
  vec4 f0_alpha;       // F0, GGX alpha
  vec4 emission;       // emitted radiance
  uvec4 flags;         // x emissive, y roughness level
};

struct GpuEmitter {
  ivec4 voxel_face;  // global voxel, face 0..5
  vec4 radiance;
};

// One texel of one baked face: slot packed i | j << 8 | k << 16, level | face << 4 | S << 8
// (kJobFootprintSobol or'ed in), i | j << 16, the index of its slot-set owner among the
// batch's owners (an RDM, or a radiance map's slot; slot-set recording).
// kJobFootprintSobol: a radiance-map texel of the prefiltered estimator (level 0), whose
// footprint points are Owen-scrambled Sobol points (shared/rdm_sobol.h), not hashed uniforms.
// A face-light job (docs/spec.md section 3.2): level kFaceLightLevel, S = 0, data.z the face's
// faceLightTexel (voxel index * 6 + face), which the path key's texel then reads as is, and
// data.w the float bits of its slot's local emitter CDF mass (detail::faceLightLocalSum).
RDM_GPU_CONST uint kJobFootprintSobol = 1u << 31;
RDM_GPU_CONST uint kJobSizeMask = 0xffffu;  // S = (data.y >> 8) & kJobSizeMask
struct GpuJob {
  uvec4 data;
};

// The whole state of a suspended path: enough to continue bit for bit.
struct GpuPathState {
  vec4 origin;       // segment origin (voxel units), w last bsdf pdf
  vec4 dir;          // segment direction, w origin sample weight
  vec4 throughput;   // xyz, w walk time t
  vec4 radiance;     // xyz, w unused
  vec4 vertex;       // hit point x_k, w unused
  vec4 shadow_dir;   // shadow ray direction, w unused
  vec4 pending;      // next-event contribution added if the shadow ray agrees
  ivec4 cell;        // walk cell xyz, w walk crossing mask
  ivec4 target;      // emitter voxel xyz, w its face's axis
  uvec4 control;     // phase, bounce k, flags | face << 8 | palette << 16, walk step
};

struct GpuCounters {
  uvec4 values;  // x paths still active, y rays (low 32 bits), z rays (carry), w unused
};

// Push constants of the bake kernel.
struct GpuPush {
  uvec4 batch;  // texel jobs, samples per job, first sample, loop budget
};

// The prefilter pass (shaders/prefilter.comp): rough levels of the prefiltered estimator
// derived from finished radiance maps with the CPU's kernels (rdm/bake/prefilter.h), bound in
// a descriptor set of its own.
RDM_GPU_CONST int kBindingMapTexels = 0;      // GpuMapTexel[]: finished maps, mips concatenated
RDM_GPU_CONST int kBindingKernelBegin = 1;    // uint[]: every kernel's begin[], into the taps
RDM_GPU_CONST int kBindingKernelTaps = 2;     // GpuKernelTap[]: every kernel's taps
RDM_GPU_CONST int kBindingDeriveTasks = 3;    // GpuDeriveTask[]: one per derived RDM face
RDM_GPU_CONST int kBindingDerivedTexels = 4;  // GpuMapTexel[]: the derived faces' texels

struct GpuMapTexel {
  vec4 mean;      // xyz
  vec4 variance;  // xyz, of the mean
};

struct GpuKernelTap {
  uvec4 tap;  // x map texel (index into the map's concatenated mips), y weight bits
};

// One derived face: the map's first texel, the kernel's first begin[] entry, the first
// derived texel, the face's texel count (S^2).
struct GpuDeriveTask {
  uvec4 data;
};

#ifdef __cplusplus
static_assert(sizeof(GpuMapTexel) == 32);
static_assert(sizeof(GpuKernelTap) == 16);
static_assert(sizeof(GpuDeriveTask) == 16);
static_assert(sizeof(GpuCamera) == 64);
static_assert(sizeof(GpuParams) == 192);
static_assert(offsetof(GpuParams, camera) == 128);
static_assert(offsetof(GpuParams, sun_direction) == 32);
static_assert(offsetof(GpuParams, sky_ground) == 112);
static_assert(sizeof(GpuMaterial) == 64);
static_assert(offsetof(GpuMaterial, flags) == 48);
static_assert(sizeof(GpuEmitter) == 32);
static_assert(sizeof(GpuJob) == 16);
static_assert(sizeof(GpuPathState) == 160);
static_assert(offsetof(GpuPathState, cell) == 112);
static_assert(offsetof(GpuPathState, control) == 144);
static_assert(sizeof(GpuCounters) == 16);
static_assert(sizeof(GpuPush) == 16);
}  // namespace rdm::gpu
#endif
#undef RDM_GPU_CONST
#endif  // RDM_GPU_LAYOUT_H
