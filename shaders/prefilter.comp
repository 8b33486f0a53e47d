// Prefilter pass of the prefiltered estimator (docs/spec.md section 3.1, docs/vulkan.md): each
// invocation derives one texel of a rough level of an RDM face from its face's finished
// radiance map, with the kernel the CPU applies (rdm::applyKernel): the weighted sum of the
// map's taps, and the sum of squared weights times their variances, in tap order, in float.
// Invocation x derives texel x of all the pass's derived faces, found by a binary search of the
// tasks (in derived-texel order): one flat dispatch, so faces of every size fill the lanes.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "shared/rdm_gpu_layout.h"

layout(local_size_x = kWorkgroupSize) in;

layout(std430, set = 0, binding = kBindingMapTexels) readonly buffer MapBuffer { GpuMapTexel map_texels[]; };
layout(std430, set = 0, binding = kBindingKernelBegin) readonly buffer BeginBuffer { uint kernel_begin[]; };
layout(std430, set = 0, binding = kBindingKernelTaps) readonly buffer TapsBuffer { GpuKernelTap kernel_taps[]; };
layout(std430, set = 0, binding = kBindingDeriveTasks) readonly buffer TasksBuffer { GpuDeriveTask tasks[]; };
layout(std430, set = 0, binding = kBindingDerivedTexels) writeonly buffer OutBuffer { GpuMapTexel derived[]; };
layout(push_constant) uniform PushBlock { GpuPush push; };  // batch: tasks, derived texels

void main() {
  const uint id = gl_GlobalInvocationID.x;
  if (id >= push.batch.y) return;
  uint lo = 0u, hi = push.batch.x;  // the last task whose first derived texel is <= id
  while (hi - lo > 1u) {
    const uint mid = (lo + hi) / 2u;
    if (tasks[mid].data.z <= id) lo = mid; else hi = mid;
  }
  const uvec4 task = tasks[lo].data;
  const uint texel = id - task.z;
  vec3 mean = vec3(0.0f), variance = vec3(0.0f);
  const uint first = kernel_begin[task.y + texel], last = kernel_begin[task.y + texel + 1u];
  for (uint t = first; t < last; ++t) {
    const uvec4 tap = kernel_taps[t].tap;
    const float w = uintBitsToFloat(tap.y);
    const GpuMapTexel m = map_texels[task.x + tap.x];
    mean += w * m.mean.xyz;
    variance += (w * w) * m.variance.xyz;
  }
  derived[id].mean = vec4(mean, 0.0f);
  derived[id].variance = vec4(variance, 0.0f);
}
