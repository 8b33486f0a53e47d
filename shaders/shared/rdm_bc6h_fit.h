// The endpoint fit of the BC6H encoder (docs/bc6h.md, "Encoder"), shared by the CPU
// (libs/image/src/bc6h_encode.cpp) and Vulkan (shaders/bc6h_encode.comp): a region's principal
// axis by integer power iteration, its endpoints at the texels' extreme projections, and
// least-squares endpoints for fixed indices. Only 32-bit integer arithmetic, every product
// bounded below 2^31 (the bounds are noted), and divisions of non-negative values, so every
// device computes the same endpoints. Written in the common subset of GLSL 4.50 and C++.
//
// Units: texels are half bit patterns (0..0x7BFF). Endpoints are in the same space with 4
// fractional bits ("Q4"); a Q4 value h16 stands for the unquantized value (h16 / 16 + 0.5) *
// 64 / 31, the centre of the unquantized values that decode to h (the decoder's last step is
// h = u * 31 >> 6).
#ifndef RDM_BC6H_FIT_H
#define RDM_BC6H_FIT_H

#include "rdm_bc6h.h"

#ifdef __cplusplus
#include <bit>
#endif

#ifdef __cplusplus
namespace rdm::shared {
#define RDM_FN inline
#define RDM_CONST constexpr
#define RDM_INOUT(T) T&
#define RDM_IN(T) const T&
#else
#define RDM_FN
#define RDM_CONST const
#define RDM_INOUT(T) inout T
#define RDM_IN(T) in T
#endif

RDM_CONST int kBc6hMaxQ4 = 31743 * 16;  // unquantized 65535's half value, Q4
RDM_CONST int kBc6hFitBits = 12;        // a region's texels are fitted at 12-bit precision
RDM_CONST int kBc6hPowerIterations = 8;
RDM_CONST int kBc6hAxisOne = 4096;  // the axis's largest component after each iteration
RDM_CONST uint kBc6hErrorMax = 0xFFFFFFFFu;

// A block's texels: half bit patterns after the input contract, texel x + 4 y. `count` is
// always 16; the Vulkan pass sets it from a push constant, so that the compiler keeps the
// texel loops as loops (unrolled 16-fold and nested, lavapipe took minutes to compile them).
struct Bc6hSource {
  ivec3 h[16];
  int count;
};

// Endpoints a (e = 2 s) and b (e = 2 s + 1) of subsets s = 0, 1, Q4.
struct Bc6hLines {
  ivec3 e[4];
};

// A block's indices, texel x + 4 y.
struct Bc6hIndices {
  int k[16];
};

struct Bc6hFit {
  ivec3 a, b;     // Q4
  uint residual;  // squared distance of the texels from the axis, half bits^2, saturated
};

// The bits needed for x (0 for 0); no loop, since lavapipe counts back-edges.
#ifdef __cplusplus
RDM_FN int bc6hBitLength(uint x) { return int(std::bit_width(x)); }
#else
RDM_FN int bc6hBitLength(uint x) { return findMSB(x) + 1; }
#endif

// round(num / den) for den > 0, halves away from zero, the same on every device.
RDM_FN int bc6hDivRound(int num, int den) {
  return num >= 0 ? (num + den / 2) / den : -((den / 2 - num) / den);
}
RDM_FN ivec3 bc6hDivRound3(ivec3 num, int den) {
  return ivec3(bc6hDivRound(num.x, den), bc6hDivRound(num.y, den), bc6hDivRound(num.z, den));
}
RDM_FN int bc6hMaxAbs(ivec3 v) {
  return max(max(abs(v.x), abs(v.y)), abs(v.z));
}

// Where a subset's texels lie: their smallest value per channel and the right shift that
// brings their extent under 2^kBc6hFitBits.
struct Bc6hFrame {
  ivec3 lo;
  int shift, count;
};

RDM_FN Bc6hFrame bc6hFrameOf(RDM_IN(Bc6hSource) src, int regions, int part, int subset) {
  Bc6hFrame f;
  f.lo = ivec3(kBc6hMaxHalf);
  ivec3 hi = ivec3(0);
  f.count = 0;
  for (int t = 0; t < src.count; ++t) {
    if (bc6hSubset(regions, part, t) != subset) continue;
    f.lo = min(f.lo, src.h[t]);
    hi = max(hi, src.h[t]);
    ++f.count;
  }
  f.shift = max(0, bc6hBitLength(uint(bc6hMaxAbs(hi - f.lo))) - kBc6hFitBits);
  return f;
}

// Texel t in the frame: 0 .. 2^12 - 1 per channel.
RDM_FN ivec3 bc6hFramed(RDM_IN(Bc6hSource) src, Bc6hFrame f, int t) {
  return (src.h[t] - f.lo) >> f.shift;
}

// A framed Q4 value back to half space, clamped to the unquantized range.
RDM_FN ivec3 bc6hUnframe(Bc6hFrame f, ivec3 q4) {
  q4 = clamp(q4, ivec3(-(1 << 19)), ivec3(1 << 19));  // |q4| << 3 stays below 2^23
  return clamp(f.lo * 16 + q4 * (1 << f.shift), ivec3(0), ivec3(kBc6hMaxQ4));
}

// The principal axis of a covariance (diagonal xx yy zz, off-diagonal xy xz yz; entries below
// 2^15), by power iteration from `axis`; its largest component is kBc6hAxisOne, or it is 0.
RDM_FN ivec3 bc6hPrincipalAxis(ivec3 diag, ivec3 off, ivec3 axis) {
  for (int i = 0; i < kBc6hPowerIterations; ++i) {
    // |entry| < 2^15, |axis| <= 2^15 (the start) or 2^12: each sum stays below 2^31.
    ivec3 next = ivec3(diag.x * axis.x + off.x * axis.y + off.y * axis.z,
                       off.x * axis.x + diag.y * axis.y + off.z * axis.z,
                       off.y * axis.x + off.z * axis.y + diag.z * axis.z);
    int largest = bc6hMaxAbs(next);
    if (largest == 0) return ivec3(0);
    int shift = max(0, bc6hBitLength(uint(largest)) - 18);  // next / 2^shift below 2^18
    next = bc6hDivRound3(next, 1 << shift);
    axis = bc6hDivRound3(next * kBc6hAxisOne, max(1, bc6hDivRound(largest, 1 << shift)));
  }
  return axis;
}

// The squared length of the offsets of framed texels from their mean, and (the covariance)
// their products, scaled so every entry is below 2^15.
RDM_FN uint bc6hMoments(RDM_IN(Bc6hSource) src, int regions, int part, int subset,
                        Bc6hFrame f, ivec3 mean4, RDM_INOUT(ivec3) diag, RDM_INOUT(ivec3) off) {
  diag = ivec3(0);
  off = ivec3(0);
  for (int t = 0; t < src.count; ++t) {
    if (bc6hSubset(regions, part, t) != subset) continue;
    ivec3 d = bc6hDivRound3(bc6hFramed(src, f, t) * 16 - mean4, 16);  // |d| < 2^12
    diag += d * d;                                                     // 16 * 2^24 = 2^28
    off += ivec3(d.x * d.y, d.x * d.z, d.y * d.z);
  }
  uint spread = uint(diag.x) + uint(diag.y) + uint(diag.z);
  int scale = 1 << max(0, bc6hBitLength(uint(max(bc6hMaxAbs(diag), bc6hMaxAbs(off)))) - 15);
  diag = bc6hDivRound3(diag, scale);
  off = bc6hDivRound3(off, scale);
  return spread;
}

// The segment of a subset's principal axis that spans its texels' projections, and the
// texels' squared distance from the axis (the partition ranking of bc6hRankPartitions).
RDM_FN Bc6hFit bc6hFitSubset(RDM_IN(Bc6hSource) src, int regions, int part, int subset) {
  Bc6hFrame f = bc6hFrameOf(src, regions, part, subset);
  ivec3 sum = ivec3(0);
  for (int t = 0; t < src.count; ++t)
    if (bc6hSubset(regions, part, t) == subset) sum += bc6hFramed(src, f, t);
  ivec3 mean4 = bc6hDivRound3(sum * 16, f.count);  // 16 * 2^12 * 16: 2^20
  ivec3 diag, off;
  uint spread = bc6hMoments(src, regions, part, subset, f, mean4, diag, off);
  ivec3 extent = ivec3(0);
  for (int t = 0; t < src.count; ++t)
    if (bc6hSubset(regions, part, t) == subset)
      extent = max(extent, bc6hFramed(src, f, t));
  ivec3 axis = bc6hPrincipalAxis(diag, off, extent);
  int length2 = max(1, bc6hDivRound(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z, 4096));
  ivec3 coarse = bc6hDivRound3(axis, 4);  // |coarse| <= 1024
  int p_min = 0, p_max = 0;
  uint along = 0u;
  for (int t = 0; t < src.count; ++t) {
    if (bc6hSubset(regions, part, t) != subset) continue;
    ivec3 d = bc6hFramed(src, f, t) * 16 - mean4;  // Q4, |d| < 2^16
    // p ~ d . axis / 4096; |d . coarse| < 3 * 2^26.
    int p = bc6hDivRound(d.x * coarse.x + d.y * coarse.y + d.z * coarse.z, 1024);
    p_min = min(p_min, p);
    p_max = max(p_max, p);
    int q = bc6hDivRound(p, 16);  // ~ the offset along the axis, framed units, below 2^14
    along += uint(q * q);
  }
  // along ~ sum (d . axis)^2 / 2^24 while spread ~ sum |d|^2 / 1; the axis's length^2 / 2^24
  // is length2 / 4096, in [1, 3].
  along = along / uint(length2) * 4096u + along % uint(length2) * 4096u / uint(length2);
  uint residual = spread > along ? spread - along : 0u;
  int scale = 2 * f.shift;
  Bc6hFit fit;
  fit.residual = residual > (kBc6hErrorMax >> uint(scale)) ? kBc6hErrorMax : residual << scale;
  // Endpoints: mean + axis * p / |axis|^2, with p ~ d . axis / 4096 and |axis|^2 ~ 4096 length2.
  fit.a = bc6hUnframe(f, mean4 + bc6hDivRound3(axis * p_min, length2));
  fit.b = bc6hUnframe(f, mean4 + bc6hDivRound3(axis * p_max, length2));
  return fit;
}

// Least-squares endpoints of one subset for fixed indices (the endpoints of the line that
// minimizes sum |x_t - (a + w_t (b - a) / 64)|^2), as a linear regression of the framed texels
// on their weights; false (the endpoints unchanged) when every texel has the same weight.
RDM_FN bool bc6hRefineSubset(RDM_IN(Bc6hSource) src, int regions, int part, int subset,
                             RDM_IN(Bc6hIndices) indices, RDM_INOUT(ivec3) a,
                             RDM_INOUT(ivec3) b) {
  Bc6hFrame f = bc6hFrameOf(src, regions, part, subset);
  int n = f.count, total = 0;
  ivec3 sum = ivec3(0);
  for (int t = 0; t < src.count; ++t) {
    if (bc6hSubset(regions, part, t) != subset) continue;
    total += bc6hWeight(regions, indices.k[t]);
    sum += bc6hFramed(src, f, t);
  }
  int svv = 0;
  ivec3 svx = ivec3(0);
  for (int t = 0; t < src.count; ++t) {
    if (bc6hSubset(regions, part, t) != subset) continue;
    int centred = n * bc6hWeight(regions, indices.k[t]) - total;  // |centred| <= 1024
    svv += centred * centred;                                   // 16 * 2^20
    svx += centred * bc6hFramed(src, f, t);                     // 16 * 2^10 * 2^12
  }
  if (svv == 0) return false;
  // slope = svx / svv per unit of weight sum; shift both so that 1024 * 16 * svx < 2^31.
  int scale = 1 << max(0, bc6hBitLength(uint(bc6hMaxAbs(svx))) - 16);
  svx = bc6hDivRound3(svx, scale);
  svv = svv / scale;
  if (svv == 0) return false;
  ivec3 mean4 = bc6hDivRound3(sum * 16, n);
  a = bc6hUnframe(f, mean4 - bc6hDivRound3(svx * (total * 16), svv));
  b = bc6hUnframe(f, mean4 + bc6hDivRound3(svx * ((64 * n - total) * 16), svv));
  return true;
}

#ifdef __cplusplus
}  // namespace rdm::shared
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#undef RDM_IN
#endif
#endif  // RDM_BC6H_FIT_H
