// BC6H_UFLOAT encoder (docs/bc6h.md): invocation i encodes block i of a band of block rows with
// shaders/shared/rdm_bc6h_encode.h, the encoder the CPU runs (rdm::encodeBc6hBlock), so the
// blocks are the CPU's bit for bit. Texels are read as float bits and converted to half by
// integer code: no float operation touches them.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "shared/rdm_bc6h_encode.h"
#include "shared/rdm_gpu_layout.h"

layout(local_size_x = kWorkgroupSize) in;

// Row-major texels of the band, `channels` floats each (R, G, B first), as their bits.
layout(std430, set = 0, binding = 0) readonly buffer TexelBuffer { uint texels[]; };
layout(std430, set = 0, binding = 1) writeonly buffer BlockBuffer { uvec4 blocks[]; };
// x: width in texels, y: channels per texel, z: mode set (kBc6hModes*) + 256 * texels per
// block (16, the loop bound Bc6hSource::count), w: blocks in the band.
layout(push_constant) uniform PushBlock { uvec4 band; };

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= band.w) return;
  uint wide = band.x / 4u;
  uint bx = id % wide, by = id / wide;
  Bc6hSource src;
  src.count = int(band.z >> 8);
  for (int t = 0; t < src.count; ++t) {
    uint at = ((by * 4u + uint(t / 4)) * band.x + bx * 4u + uint(t % 4)) * band.y;
    src.h[t] = ivec3(bc6hInputHalf(texels[at]), bc6hInputHalf(texels[at + 1u]),
                     bc6hInputHalf(texels[at + 2u]));
  }
  blocks[id] = bc6hEncodeBlock(src, int(band.z & 255u));
}
