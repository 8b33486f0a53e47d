// Radical inverses (van der Corput, Halton) and Owen-scrambled 2D Sobol points (docs/spec.md
// section 3.1): the first two Sobol dimensions, whose first 2^m points stratify every elementary
// interval of area 2^-m, each randomised by a hashed nested uniform scramble (Laine and Karras
// 2011, Burley 2020). Keyed per texel, so results stay a pure function of (texel key, sample
// index). The index is not shuffled: one pair of dimensions needs no decorrelation from another,
// and small indices keep the dimension-1 loop short.
#pragma once

#include <cstdint>

namespace rdm {

inline uint32_t reverseBits(uint32_t x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
}

// Radical inverse of `index` in base 2 (the van der Corput sequence, Sobol dimension 0),
// exact in float for index < 2^24.
inline float radicalInverse2(uint32_t index) {
  return float(reverseBits(index) >> 8) * (1.0f / 16777216.0f);
}

// Radical inverse of `index` in `base` >= 2: the Halton sequence's coordinate of that base.
inline float radicalInverse(uint32_t base, uint32_t index) {
  const float inverse = 1.0f / float(base);
  float scale = inverse, result = 0.0f;
  for (; index > 0; index /= base, scale *= inverse) result += float(index % base) * scale;
  return result;
}

// A permutation of 32-bit words in which output bit k depends only on input bits 0..k (each
// step is x + c or x ^ x * even): applied to bit-reversed values it is a nested uniform
// scramble, a random permutation of every dyadic interval's two halves, which keeps every
// (0, m, 2)-net a net.
inline uint32_t nestedPermutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x3d4d51c2u;
  x ^= x * 0xa31e0b74u;
  x ^= x * 0x5f0c8c9eu;
  x ^= x * 0x9e3779b8u;
  return x;
}

inline uint32_t owenScramble(uint32_t x, uint32_t seed) {
  return reverseBits(nestedPermutation(reverseBits(x), seed));
}

// Sobol dimension 1 (generator: the Pascal matrix mod 2), as a 0.32 fixed-point value.
inline uint32_t sobolDimension1(uint32_t index) {
  uint32_t v = 1u << 31, r = 0;
  for (; index != 0; index >>= 1, v ^= v >> 1) {
    if (index & 1u) r ^= v;
  }
  return r;
}

struct Point2 {
  float u0, u1;  // in [0, 1)
};

// Sample `index` of the scrambled sequence with key `seed`.
inline Point2 owenSobol2(uint32_t index, uint32_t seed) {
  const uint32_t x = owenScramble(reverseBits(index), seed ^ 0x85ebca6bu);
  const uint32_t y = owenScramble(sobolDimension1(index), seed ^ 0xc2b2ae35u);
  return {float(x >> 8) * (1.0f / 16777216.0f), float(y >> 8) * (1.0f / 16777216.0f)};
}

}  // namespace rdm
