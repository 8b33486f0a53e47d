// The BC6H_UFLOAT block encoder (docs/bc6h.md, "Encoder"), the one implementation the CPU
// (rdm::encodeBc6hBlock) and Vulkan (shaders/bc6h_encode.comp) run: per mode and partition,
// endpoints from rdm_bc6h_fit.h, quantized, indices chosen exhaustively against the decoder's
// palette, refined by least squares; the best block of each stage of the mode search polished
// by one-step endpoint moves. Only 32-bit integer arithmetic, so the blocks are the same on
// every device. The error is the squared difference of decoded and source half bit patterns,
// saturated at 2^32 - 1. Written in the common subset of GLSL 4.50 and C++.
//
// lavapipe stops a shader after 65,535 loop back-edges (docs/spec.md section 9); the worst
// block takes about 30,000 (every stage, every mode, both partitions), so loops over channels
// are vector operations and functions have one call site where it matters.
#ifndef RDM_BC6H_ENCODE_H
#define RDM_BC6H_ENCODE_H

#include "rdm_bc6h_fit.h"

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

// Mode sets (rdm::Bc6hModeSet): mode 11 only; modes 11..14; all 14.
RDM_CONST int kBc6hModesMode11 = 0;
RDM_CONST int kBc6hModesOneRegion = 1;
RDM_CONST int kBc6hModesAll = 2;
RDM_CONST int kBc6hRefinements = 2;  // least-squares passes after the principal-axis fit
// Two regions are tried only when one region leaves more than this squared half-bit error in
// the block's 48 values (an RMS of 4 half bits, about 0.4 %): below it they almost never win
// and would cost most of the encode time.
RDM_CONST uint kBc6hTwoRegionMinError = 768u;

struct Bc6hCandidate {
  uint error;
  int mode;  // 0..13; -1: none yet
  int part;
  ivec3 values[4];  // endpoint values as the decoder sees them (deltas undone)
  Bc6hIndices indices;
};

// The `bits`-bit endpoint value whose unquantized value is nearest the Q4 half value h16.
RDM_FN int bc6hQuantize(int h16, int bits) {
  int target = 64 * h16 + 512;  // 496 times the unquantized target, below 2^25
  int u = min(65535, bc6hDivRound(target, 496));
  if (bits >= 16) return u;
  int top = (1 << bits) - 1;
  int best = min(top, (u << bits) >> 16);
  int guess = best;
  int miss = abs(496 * bc6hUnquantize(best, bits) - target);
  if (guess > 0 && abs(496 * bc6hUnquantize(guess - 1, bits) - target) < miss) {
    best = guess - 1;
    miss = abs(496 * bc6hUnquantize(best, bits) - target);
  }
  if (guess < top && abs(496 * bc6hUnquantize(guess + 1, bits) - target) < miss) best = guess + 1;
  return best;
}

RDM_FN int bc6hDeltaReach(int mode, int channel) {
  return 1 << (kBc6hDeltaBits[3 * mode + channel] - 1);
}

// Whether a transformed mode can store the candidate's deltas (always, untransformed).
RDM_FN bool bc6hStorable(RDM_IN(Bc6hCandidate) c) {
  if (!kBc6hModeTransformed[c.mode]) return true;
  ivec3 reach = ivec3(bc6hDeltaReach(c.mode, 0), bc6hDeltaReach(c.mode, 1),
                      bc6hDeltaReach(c.mode, 2));
  for (int e = 1; e < 2 * kBc6hModeRegions[c.mode]; ++e) {
    ivec3 delta = c.values[e] - c.values[0];
    if (any(lessThan(delta, -reach)) || any(greaterThanEqual(delta, reach))) return false;
  }
  return true;
}

// The endpoint values of `lines` in the candidate's mode, deltas clamped to their range in
// transformed modes.
RDM_FN void bc6hQuantizeLines(RDM_IN(Bc6hLines) lines, RDM_INOUT(Bc6hCandidate) c) {
  int bits = kBc6hEndpointBits[c.mode];
  for (int e = 0; e < 4; ++e) {
    c.values[e] = ivec3(0);
    if (e >= 2 * kBc6hModeRegions[c.mode]) continue;
    c.values[e] = ivec3(bc6hQuantize(lines.e[e].x, bits), bc6hQuantize(lines.e[e].y, bits),
                        bc6hQuantize(lines.e[e].z, bits));
  }
  if (!kBc6hModeTransformed[c.mode]) return;
  ivec3 reach = ivec3(bc6hDeltaReach(c.mode, 0), bc6hDeltaReach(c.mode, 1),
                      bc6hDeltaReach(c.mode, 2));
  for (int e = 1; e < 2 * kBc6hModeRegions[c.mode]; ++e)
    c.values[e] = c.values[0] + clamp(c.values[e] - c.values[0], -reach, reach - 1);
}

// Picks each texel's index against the decoded palette (an anchor's from the palette's lower
// half, so its implicit top bit is 0) and sets the candidate's error.
RDM_FN void bc6hChooseIndices(RDM_IN(Bc6hSource) src, RDM_INOUT(Bc6hCandidate) c) {
  int regions = kBc6hModeRegions[c.mode], bits = kBc6hEndpointBits[c.mode];
  int count = 1 << bc6hIndexBits(regions);
  ivec3 palette[32];
  for (int i = 0; i < regions * count; ++i) {
    int s = i / count, k = i % count;
    ivec3 a = c.values[2 * s], b = c.values[2 * s + 1];
    palette[i] = bc6hInterpolate3(
        ivec3(bc6hUnquantize(a.x, bits), bc6hUnquantize(a.y, bits), bc6hUnquantize(a.z, bits)),
        ivec3(bc6hUnquantize(b.x, bits), bc6hUnquantize(b.y, bits), bc6hUnquantize(b.z, bits)),
        bc6hWeight(regions, k));
  }
  uint total = 0u;
  for (int t = 0; t < src.count; ++t) {
    int first = bc6hSubset(regions, c.part, t) * count;
    int limit = bc6hIsAnchor(regions, c.part, t) ? count / 2 : count;
    uint best = kBc6hErrorMax;
    for (int k = 0; k < limit; ++k) {
      ivec3 d = palette[first + k] - src.h[t];  // each square below 2^30
      uint error = uint(d.x * d.x) + uint(d.y * d.y) + uint(d.z * d.z);
      if (error < best) {
        best = error;
        c.indices.k[t] = k;
      }
    }
    total = total > kBc6hErrorMax - best ? kBc6hErrorMax : total + best;
  }
  c.error = total;
}

// Orders each subset's endpoints so that its anchor texel lies nearer the first.
RDM_FN void bc6hOrient(RDM_IN(Bc6hSource) src, int regions, int part,
                       RDM_INOUT(Bc6hLines) lines) {
  for (int s = 0; s < regions; ++s) {
    ivec3 x = src.h[s == 0 ? 0 : kBc6hAnchors[part]] * 16;
    ivec3 da = bc6hDivRound3(x - lines.e[2 * s], 16), db = bc6hDivRound3(x - lines.e[2 * s + 1], 16);
    uint to_a = uint(da.x * da.x) + uint(da.y * da.y) + uint(da.z * da.z);
    uint to_b = uint(db.x * db.x) + uint(db.y * db.y) + uint(db.z * db.z);
    if (to_b < to_a) {
      ivec3 swap = lines.e[2 * s];
      lines.e[2 * s] = lines.e[2 * s + 1];
      lines.e[2 * s + 1] = swap;
    }
  }
}

// Encodes with one mode and partition from fitted lines; keeps the better of `best` and each
// least-squares pass.
RDM_FN void bc6hTryMode(RDM_IN(Bc6hSource) src, int mode, int part, Bc6hLines lines,
                        RDM_INOUT(Bc6hCandidate) best) {
  int regions = kBc6hModeRegions[mode];
  bc6hOrient(src, regions, part, lines);
  for (int pass = 0; pass <= kBc6hRefinements; ++pass) {
    Bc6hCandidate c;
    c.mode = mode;
    c.part = part;
    bc6hQuantizeLines(lines, c);
    bc6hChooseIndices(src, c);
    if (c.error < best.error || best.mode < 0) best = c;
    if (c.error == 0u || pass == kBc6hRefinements) return;
    for (int s = 0; s < regions; ++s)
      bc6hRefineSubset(src, regions, part, s, c.indices, lines.e[2 * s], lines.e[2 * s + 1]);
  }
}

// One round of single-channel endpoint moves by one quantization step, each kept when it lowers
// the error.
RDM_FN void bc6hPolish(RDM_IN(Bc6hSource) src, RDM_INOUT(Bc6hCandidate) best) {
  int top = (1 << kBc6hEndpointBits[best.mode]) - 1;
  int trials = 12 * kBc6hModeRegions[best.mode];  // endpoint, channel, step -1 / +1
  for (int i = 0; i < trials && best.error > 0u; ++i) {
    int e = i / 6, channel = (i / 2) % 3;
    Bc6hCandidate c = best;
    c.values[e][channel] += i % 2 == 0 ? -1 : 1;
    if (c.values[e][channel] < 0 || c.values[e][channel] > top || !bc6hStorable(c)) continue;
    bc6hChooseIndices(src, c);
    if (c.error < best.error) best = c;
  }
}

// Ranks the 32 partitions by their subsets' squared distances from their principal axes and
// returns the best two (ties: the lower partition) with their fitted lines.
RDM_FN void bc6hRankPartitions(RDM_IN(Bc6hSource) src, RDM_INOUT(ivec2) chosen,
                               RDM_INOUT(Bc6hLines) first, RDM_INOUT(Bc6hLines) second) {
  uint rank0 = kBc6hErrorMax, rank1 = kBc6hErrorMax;
  chosen = ivec2(-1);
  Bc6hLines lines;
  uint residual = 0u;
  for (int j = 0; j < 4 * src.count; ++j) {  // 2 * kBc6hPartitionCount, kept a loop
    int p = j / 2, s = j % 2;
    Bc6hFit fit = bc6hFitSubset(src, 2, p, s);
    lines.e[2 * s] = fit.a;
    lines.e[2 * s + 1] = fit.b;
    residual = s == 0 ? fit.residual
                      : (residual > kBc6hErrorMax - fit.residual ? kBc6hErrorMax
                                                                 : residual + fit.residual);
    if (s == 0) continue;
    if (residual < rank0 || chosen.x < 0) {
      rank1 = rank0;
      chosen.y = chosen.x;
      second = first;
      rank0 = residual;
      chosen.x = p;
      first = lines;
    } else if (residual < rank1 || chosen.y < 0) {
      rank1 = residual;
      chosen.y = p;
      second = lines;
    }
  }
}

// The 128 bits of a candidate: mode bits, endpoint fields and partition, indices.
RDM_FN uvec4 bc6hPack(RDM_IN(Bc6hCandidate) c) {
  uvec4 block = uvec4(0u);
  int regions = kBc6hModeRegions[c.mode];
  int pos = kBc6hModeCodeBits[c.mode];
  bc6hPutBits(block, 0, pos, kBc6hModeCode[c.mode]);
  int mask = (1 << kBc6hEndpointBits[c.mode]) - 1;
  for (int f = kBc6hFieldStart[c.mode]; f < kBc6hFieldStart[c.mode + 1]; ++f) {
    uint field = kBc6hFields[f];
    int var = int(field >> 8), from = int((field >> 4) & 15u), to = int(field & 15u);
    int value = c.part;
    if (var < kBc6hPartitionVar) {
      value = c.values[var / 3][var % 3];
      if (var >= 3 && kBc6hModeTransformed[c.mode]) value = (value - c.values[0][var % 3]) & mask;
    }
    int step = from >= to ? 1 : -1, count = abs(from - to) + 1;
    for (int i = 0; i < count; ++i) bc6hPutBits(block, pos + i, 1, uint(value >> (to + step * i)));
    pos += count;
  }
  int bits = bc6hIndexBits(regions);
  for (int t = 0; t < 16; ++t) {
    int n = bc6hIsAnchor(regions, c.part, t) ? bits - 1 : bits;
    bc6hPutBits(block, pos, n, uint(c.indices.k[t]));
    pos += n;
  }
  return block;
}

// Encodes one block under the input contract with mode set `modes` (kBc6hModes*): mode 11,
// then modes 12..14, then modes 1..10 on the two best-ranked partitions when one region left
// more than kBc6hTwoRegionMinError; each stage's result is polished when it improved the block,
// so a larger mode set never does worse.
RDM_FN uvec4 bc6hEncodeBlock(RDM_IN(Bc6hSource) src, int modes) {
  Bc6hCandidate best;
  best.error = kBc6hErrorMax;
  best.mode = -1;
  Bc6hFit fit = bc6hFitSubset(src, 1, 0, 0);
  Bc6hLines one;
  one.e[0] = fit.a;
  one.e[1] = fit.b;
  one.e[2] = ivec3(0);
  one.e[3] = ivec3(0);
  Bc6hLines first = one, second = one;
  ivec2 chosen = ivec2(0);
  for (int stage = 0; stage < 3; ++stage) {
    if (stage == 1 && modes == kBc6hModesMode11) break;
    if (stage == 2 && (modes != kBc6hModesAll || best.error <= kBc6hTwoRegionMinError)) break;
    if (stage == 2) bc6hRankPartitions(src, chosen, first, second);
    uint before = best.error;
    int trials = stage == 0 ? 1 : (stage == 1 ? 3 : 20);
    for (int i = 0; i < trials && best.error > 0u; ++i) {
      int mode = stage == 0 ? 10 : (stage == 1 ? 11 + i : i % 10);
      bool later = stage == 2 && i >= 10;
      bc6hTryMode(src, mode, stage < 2 ? 0 : (later ? chosen.y : chosen.x),
                  stage < 2 ? one : (later ? second : first), best);
    }
    if (best.error < before || stage == 0) bc6hPolish(src, best);
  }
  return bc6hPack(best);
}

#ifdef __cplusplus
}  // namespace rdm::shared
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#undef RDM_IN
#endif
#endif  // RDM_BC6H_ENCODE_H
