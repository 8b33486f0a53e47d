// The cross-block denoiser (docs/denoise.md): invocation x filters texel x of the pass's
// faces with shaders/shared/rdm_denoise.h, the filter the CPU runs (rdm::denoiseRdm), walking
// the window of each of the face's up to five source faces in the CPU's order. The task of a
// texel is found by a binary search of the tasks (in output-texel order), so faces of every
// size fill one flat dispatch.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "shared/rdm_denoise.h"
#include "shared/rdm_gpu_layout.h"

layout(local_size_x = kWorkgroupSize) in;

// Source faces, S x S texels each, row-major (rdm::denoiseFaceTexels).
layout(std430, set = 0, binding = 0) readonly buffer FaceBuffer { DenoiseTexel faces[]; };
// Per filtered face: the first texel of its source faces (own first; x..w then tasks[].info.x),
// info.y: how many (1..5), info.z: S | window << 12 | radius << 20, info.w: first output texel.
struct DenoiseTask {
  uvec4 sources;
  uvec4 info;
};
layout(std430, set = 0, binding = 1) readonly buffer TaskBuffer { DenoiseTask tasks[]; };
layout(std430, set = 0, binding = 2) writeonly buffer OutBuffer { DenoiseTexel filtered[]; };
layout(std430, set = 0, binding = 3) readonly buffer ParamBuffer { DenoiseParams params; };
layout(push_constant) uniform PushBlock { GpuPush push; };  // batch: tasks, output texels

uint sourceOf(DenoiseTask task, int k) {
  return k < 4 ? task.sources[k] : task.info.x;
}

void main() {
  const uint id = gl_GlobalInvocationID.x;
  if (id >= push.batch.y) return;
  uint lo = 0u, hi = push.batch.x;  // the last task whose first output texel is <= id
  while (hi - lo > 1u) {
    const uint mid = (lo + hi) / 2u;
    if (tasks[mid].info.w <= id) lo = mid; else hi = mid;
  }
  const DenoiseTask task = tasks[lo];
  const int size = int(task.info.z & 4095u);
  const int window = int((task.info.z >> 12) & 255u), radius = int(task.info.z >> 20);
  const int texel = int(id - task.info.w);
  const int i = texel % size, j = texel / size;
  const DenoiseTexel c = faces[task.sources.x + uint(texel)];
  if (!denoiseNeeded(c, params.min_relative_error)) {
    filtered[id] = c;
    return;
  }
  float nearest = c.rgbz.w;
  for (int y = max(0, j - radius); y <= min(size - 1, j + radius); ++y)
    for (int x = max(0, i - radius); x <= min(size - 1, i + radius); ++x)
      nearest = denoiseNearer(nearest, faces[task.sources.x + uint(y * size + x)].rgbz.w);
  const float parallax = denoiseParallax(size, nearest);
  DenoiseSums sums;
  sums.weight = 0.0f;
  sums.rgb = vec3(0.0f);
  sums.variance = vec3(0.0f);
  for (int k = 0; k < int(task.info.y); ++k) {
    const uint base = sourceOf(task, k);
    const float shift = k == 0 ? 0.0f : parallax * parallax;
    for (int y = max(0, j - window); y <= min(size - 1, j + window); ++y) {
      for (int x = max(0, i - window); x <= min(size - 1, i + window); ++x) {
        const float d2 = float((x - i) * (x - i) + (y - j) * (y - j)) + shift;
        denoiseAddTap(sums, c, faces[base + uint(y * size + x)], d2, params);
      }
    }
  }
  filtered[id] = denoiseResult(sums, c);
}
