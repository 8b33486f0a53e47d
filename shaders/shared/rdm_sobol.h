// Owen-scrambled 2D Sobol points (docs/spec.md section 3.1), shared by the C++ core and the
// Vulkan bake kernel: the first two Sobol dimensions, whose first 2^m points stratify every
// elementary interval of area 2^-m, each randomised by a hashed nested uniform scramble (Laine
// and Karras 2011, Burley 2020). Keyed per texel, so results stay a pure function of (texel key,
// sample index). The index is not shuffled: one pair of dimensions needs no decorrelation from
// another, and small indices keep the dimension-1 loop short. Written in the common subset of
// GLSL 4.50 and C++ (rdm_shared.h's conventions); 32-bit unsigned arithmetic wraps in both.
// sobolDimension1 loops once per bit of the index (at most 32 back-edges, within the kernel's
// per-event reserve kStepReserve).
#ifndef RDM_SOBOL_H
#define RDM_SOBOL_H

#include "rdm_shared.h"

#ifdef __cplusplus
namespace rdm::shared {
#define RDM_FN inline
#else
#define RDM_FN
#endif

RDM_FN uint sobolReverseBits(uint x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
}

// A permutation of 32-bit words in which output bit k depends only on input bits 0..k (each
// step is x + c or x ^ x * even): applied to bit-reversed values it is a nested uniform
// scramble, a random permutation of every dyadic interval's two halves, which keeps every
// (0, m, 2)-net a net.
RDM_FN uint sobolNestedPermutation(uint x, uint seed) {
  x += seed;
  x ^= x * 0x3d4d51c2u;
  x ^= x * 0xa31e0b74u;
  x ^= x * 0x5f0c8c9eu;
  x ^= x * 0x9e3779b8u;
  return x;
}

RDM_FN uint sobolOwenScramble(uint x, uint seed) {
  return sobolReverseBits(sobolNestedPermutation(sobolReverseBits(x), seed));
}

// Sobol dimension 1 (generator: the Pascal matrix mod 2), as a 0.32 fixed-point value.
RDM_FN uint sobolDimension1(uint index) {
  uint v = 1u << 31, r = 0u;
  for (; index != 0u; index >>= 1, v ^= v >> 1) {
    if ((index & 1u) != 0u) r ^= v;
  }
  return r;
}

// Sample `index` of the scrambled sequence with key `seed`, in [0, 1)^2.
RDM_FN vec2 owenSobolPoint(uint index, uint seed) {
  uint x = sobolOwenScramble(sobolReverseBits(index), seed ^ 0x85ebca6bu);
  uint y = sobolOwenScramble(sobolDimension1(index), seed ^ 0xc2b2ae35u);
  return vec2(float(x >> 8) * (1.0f / 16777216.0f), float(y >> 8) * (1.0f / 16777216.0f));
}

#ifdef __cplusplus
}  // namespace rdm::shared
#endif
#undef RDM_FN
#endif  // RDM_SOBOL_H
