// The BC6H_UFLOAT block encoder (bc6h.h). Per region, endpoints start on the principal axis of
// the texels (through their mean, spanning their projections) and are then refined by least
// squares over the chosen indices. Everything is fitted in the 16-bit "unquantized" space the
// format interpolates in, where a texel's target is its half bit pattern times 64/31, and
// judged by the squared difference of decoded and source half bit patterns (docs/bc6h.md).
#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "bc6h_format.h"
#include "rdm/base/check.h"
#include "rdm/image/bc6h.h"

namespace rdm {
namespace {

using namespace bc6h;

using Vec3 = std::array<float, 3>;
constexpr float kTargetMax = 65535.0f;
constexpr int kRefinements = 2;      // least-squares passes after the principal-axis fit
constexpr int kTriedPartitions = 2;  // 2-region partitions tried per block, best fit first
constexpr int kPowerIterations = 8;
constexpr int kPolishRounds = 1;  // passes of one-step endpoint moves on the best block
// Two regions are tried only when one region leaves more than this squared half-bit error in
// the block's 48 values (an RMS of 4 half bits, about 0.4 %): below it they almost never win
// and would cost most of the encode time (docs/bc6h.md).
constexpr int64_t kTwoRegionMinError = 768;

struct Source {
  std::array<Vec3, 16> target;              // texel in unquantized space, 0..65535
  std::array<std::array<int, 3>, 16> half;  // source half bit patterns
};

struct Line {
  Vec3 a{}, b{};  // endpoints in unquantized space
};

struct Fit {
  Line line;
  float residual = 0;  // squared distance of the texels from the principal axis
};

struct Candidate {
  int64_t error = std::numeric_limits<int64_t>::max();
  const ModeInfo* mode = nullptr;
  int partition = 0;
  EndpointValues values{};  // as the decoder sees them
  std::array<int, 16> indices{};
};

Source prepare(const Bc6hTexels& texels) {
  Source source;
  for (int t = 0; t < 16; ++t)
    for (int c = 0; c < 3; ++c) {
      const int bits = Imath::half(bc6hClampInput(texels[t][c])).bits();
      source.half[t][c] = bits;
      source.target[t][c] = std::min(kTargetMax, (float(bits) + 0.5f) * 64.0f / 31.0f);
    }
  return source;
}

bool inSubset(int regions, int partition, int texel, int subset) {
  return regions == 1 ? subset == 0 : subsetOf(partition, texel) == subset;
}

Vec3 clampTarget(Vec3 v) {
  for (float& x : v) x = std::clamp(x, 0.0f, kTargetMax);
  return v;
}

// The texels' principal axis (power iteration on their covariance), unit length or zero.
Vec3 principalAxis(const std::array<float, 6>& cov, Vec3 axis) {
  for (int i = 0; i < kPowerIterations; ++i) {
    const Vec3 next = {cov[0] * axis[0] + cov[1] * axis[1] + cov[2] * axis[2],
                       cov[1] * axis[0] + cov[3] * axis[1] + cov[4] * axis[2],
                       cov[2] * axis[0] + cov[4] * axis[1] + cov[5] * axis[2]};
    const float norm = std::sqrt(next[0] * next[0] + next[1] * next[1] + next[2] * next[2]);
    if (!(norm > 1e-12f)) return {0, 0, 0};
    for (int c = 0; c < 3; ++c) axis[c] = next[c] / norm;
  }
  return axis;
}

// A subset's mean, bounding-box extent, covariance (xx, xy, xz, yy, yz, zz) and the sum of its
// squared distances from the mean.
struct Moments {
  Vec3 mean{}, extent{};
  std::array<float, 6> cov{};
  float spread = 0;
};

Moments momentsOf(const Source& source, int regions, int partition, int subset) {
  Moments m;
  Vec3 lo{kTargetMax, kTargetMax, kTargetMax}, hi{};
  int count = 0;
  for (int t = 0; t < 16; ++t) {
    if (!inSubset(regions, partition, t, subset)) continue;
    ++count;
    for (int c = 0; c < 3; ++c) {
      m.mean[c] += source.target[t][c];
      lo[c] = std::min(lo[c], source.target[t][c]);
      hi[c] = std::max(hi[c], source.target[t][c]);
    }
  }
  for (int c = 0; c < 3; ++c) m.mean[c] /= float(count), m.extent[c] = hi[c] - lo[c];
  for (int t = 0; t < 16; ++t) {
    if (!inSubset(regions, partition, t, subset)) continue;
    const Vec3& x = source.target[t];
    const Vec3 d = {x[0] - m.mean[0], x[1] - m.mean[1], x[2] - m.mean[2]};
    m.cov[0] += d[0] * d[0], m.cov[1] += d[0] * d[1], m.cov[2] += d[0] * d[2];
    m.cov[3] += d[1] * d[1], m.cov[4] += d[1] * d[2], m.cov[5] += d[2] * d[2];
    m.spread += d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  }
  return m;
}

// The segment of the subset's principal axis that spans its texels' projections.
Fit fitSubset(const Source& source, int regions, int partition, int subset) {
  const Moments m = momentsOf(source, regions, partition, subset);
  const Vec3 axis = principalAxis(m.cov, m.extent);
  float p_min = 0, p_max = 0, along = 0;
  for (int t = 0; t < 16; ++t) {
    if (!inSubset(regions, partition, t, subset)) continue;
    const Vec3& x = source.target[t];
    const float p =
        (x[0] - m.mean[0]) * axis[0] + (x[1] - m.mean[1]) * axis[1] + (x[2] - m.mean[2]) * axis[2];
    p_min = std::min(p_min, p), p_max = std::max(p_max, p), along += p * p;
  }
  Fit fit;
  for (int c = 0; c < 3; ++c) {
    fit.line.a[c] = m.mean[c] + axis[c] * p_min;
    fit.line.b[c] = m.mean[c] + axis[c] * p_max;
  }
  fit.line = {clampTarget(fit.line.a), clampTarget(fit.line.b)};
  fit.residual = std::max(0.0f, m.spread - along);
  return fit;
}

float distanceSquared(const Vec3& x, const Vec3& y) {
  return (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
         (x[2] - y[2]) * (x[2] - y[2]);
}

// Orders each subset's endpoints so that its anchor texel lies nearer the first: the anchor's
// index is stored without its top bit.
void orient(const Source& source, int regions, int partition, std::array<Line, 2>& lines) {
  for (int s = 0; s < regions; ++s) {
    const Vec3& x = source.target[s == 0 ? 0 : anchorOf(partition)];
    if (distanceSquared(x, lines[s].b) < distanceSquared(x, lines[s].a))
      std::swap(lines[s].a, lines[s].b);
  }
}

// The `bits`-bit endpoint value whose unquantized value is nearest `target`.
int quantizeChannel(float target, int bits) {
  const int max = (1 << bits) - 1;
  if (bits >= 16) return std::clamp(int(target + 0.5f), 0, max);
  const int guess = std::clamp(int(target * float(1 << bits) / 65536.0f), 0, max);
  int best = guess;
  for (int q = std::max(0, guess - 1); q <= std::min(max, guess + 1); ++q)
    if (std::abs(float(unquantize(q, bits)) - target) <
        std::abs(float(unquantize(best, bits)) - target))
      best = q;
  return best;
}

// The block fields of endpoint values `values`; false when a transformed mode cannot store a
// delta.
bool storedFields(const ModeInfo& mode, const EndpointValues& values, EndpointValues& stored) {
  stored = values;
  if (!mode.transformed) return true;
  for (int e = 1; e < 2 * mode.regions; ++e)
    for (int c = 0; c < 3; ++c) {
      const int bits = mode.delta_bits[c];
      const int delta = values[e][c] - values[0][c];
      if (delta < -(1 << (bits - 1)) || delta >= (1 << (bits - 1))) return false;
      stored[e][c] = delta & ((1 << bits) - 1);
    }
  return true;
}

// The endpoint values of the lines in `mode`, deltas clamped to their range in transformed
// modes.
EndpointValues quantizeLines(const ModeInfo& mode, const std::array<Line, 2>& lines) {
  EndpointValues values{};
  for (int e = 0; e < 2 * mode.regions; ++e)
    for (int c = 0; c < 3; ++c) {
      const Line& line = lines[e / 2];
      values[e][c] = quantizeChannel(e % 2 ? line.b[c] : line.a[c], mode.endpoint_bits);
    }
  if (!mode.transformed) return values;
  for (int e = 1; e < 2 * mode.regions; ++e)
    for (int c = 0; c < 3; ++c) {
      const int reach = 1 << (mode.delta_bits[c] - 1);
      values[e][c] = values[0][c] + std::clamp(values[e][c] - values[0][c], -reach, reach - 1);
    }
  return values;
}

bool isAnchor(int regions, int partition, int texel) {
  return texel == 0 || (regions == 2 && texel == anchorOf(partition));
}

// Picks each texel's index (an anchor's from the lower half of the palette) and returns the
// block's squared error in half bits.
int64_t chooseIndices(const ModeInfo& mode, int partition, const EndpointValues& values,
                      const Source& source, std::array<int, 16>& indices) {
  const int count = 1 << indexBits(mode.regions);
  std::array<std::array<std::array<int, 3>, 16>, 2> palette{};
  for (int s = 0; s < mode.regions; ++s)
    for (int k = 0; k < count; ++k)
      for (int c = 0; c < 3; ++c)
        palette[s][k][c] = interpolateToHalf(unquantize(values[2 * s][c], mode.endpoint_bits),
                                             unquantize(values[2 * s + 1][c], mode.endpoint_bits),
                                             weightOf(mode.regions, k));
  int64_t total = 0;
  for (int t = 0; t < 16; ++t) {
    const int s = mode.regions == 2 ? subsetOf(partition, t) : 0;
    const int limit = isAnchor(mode.regions, partition, t) ? count / 2 : count;
    int64_t best = std::numeric_limits<int64_t>::max();
    for (int k = 0; k < limit; ++k) {
      int64_t error = 0;
      for (int c = 0; c < 3; ++c) {
        const int64_t d = palette[s][k][c] - source.half[t][c];
        error += d * d;
      }
      if (error < best) best = error, indices[t] = k;
    }
    total += best;
  }
  return total;
}

// Least-squares endpoints for fixed indices: minimizes the sum over a subset's texels of
// |(1 - w) a + w b - target|^2, w the index's weight / 64. Keeps a subset's line when all its
// texels share one weight.
std::array<Line, 2> refine(const ModeInfo& mode, int partition, const std::array<int, 16>& indices,
                           const Source& source, std::array<Line, 2> lines) {
  for (int s = 0; s < mode.regions; ++s) {
    double aa = 0, ab = 0, bb = 0;
    std::array<double, 3> xa{}, xb{};
    for (int t = 0; t < 16; ++t) {
      if (!inSubset(mode.regions, partition, t, s)) continue;
      const double w = weightOf(mode.regions, indices[t]) / 64.0;
      aa += (1 - w) * (1 - w), ab += (1 - w) * w, bb += w * w;
      for (int c = 0; c < 3; ++c)
        xa[c] += (1 - w) * source.target[t][c], xb[c] += w * source.target[t][c];
    }
    const double det = aa * bb - ab * ab;
    if (!(std::abs(det) > 1e-9)) continue;
    for (int c = 0; c < 3; ++c) {
      lines[s].a[c] = float((bb * xa[c] - ab * xb[c]) / det);
      lines[s].b[c] = float((aa * xb[c] - ab * xa[c]) / det);
    }
    lines[s] = {clampTarget(lines[s].a), clampTarget(lines[s].b)};
  }
  return lines;
}

Bc6hBlock pack(const Candidate& candidate) {
  const ModeInfo& mode = *candidate.mode;
  EndpointValues stored;
  RDM_CHECK(storedFields(mode, candidate.values, stored));
  Bc6hBlock block{};
  writeEndpoints(block, mode, stored, candidate.partition);
  const int bits = indexBits(mode.regions);
  int pos = indexStart(mode.regions);
  for (int t = 0; t < 16; ++t) {
    const int n = isAnchor(mode.regions, candidate.partition, t) ? bits - 1 : bits;
    writeBits(block, pos, n, uint32_t(candidate.indices[t]));
    pos += n;
  }
  return block;
}

// Encodes with one mode and partition from the fitted lines; keeps the better of `best` and
// each refinement pass.
void tryMode(const ModeInfo& mode, int partition, std::array<Line, 2> lines, const Source& source,
             Candidate& best) {
  orient(source, mode.regions, partition, lines);
  for (int pass = 0; pass <= kRefinements; ++pass) {
    Candidate candidate{0, &mode, partition, quantizeLines(mode, lines), {}};
    candidate.error = chooseIndices(mode, partition, candidate.values, source, candidate.indices);
    if (candidate.error < best.error) best = candidate;
    if (candidate.error == 0) return;
    lines = refine(mode, partition, candidate.indices, source, lines);
  }
}

// Steps single endpoint channels of `best` by one quantization step while that lowers the error.
void polish(const Source& source, Candidate& best) {
  const ModeInfo& mode = *best.mode;
  const int max = (1 << mode.endpoint_bits) - 1;
  for (int round = 0; round < kPolishRounds && best.error > 0; ++round) {
    bool improved = false;
    for (int e = 0; e < 2 * mode.regions; ++e)
      for (int c = 0; c < 3; ++c)
        for (int step : {-1, 1}) {
          Candidate trial = best;
          trial.values[e][c] += step;
          EndpointValues stored;
          if (trial.values[e][c] < 0 || trial.values[e][c] > max ||
              !storedFields(mode, trial.values, stored))
            continue;
          trial.error = chooseIndices(mode, best.partition, trial.values, source, trial.indices);
          if (trial.error < best.error) best = trial, improved = true;
        }
    if (!improved) return;
  }
}

// Modes first..last of one region, from the principal-axis fit.
void tryOneRegion(const Source& source, int first, int last, Candidate& best) {
  const Fit fit = fitSubset(source, 1, 0, 0);
  for (int number = first; number <= last && best.error > 0; ++number)
    tryMode(kModes[number - 1], 0, {fit.line, fit.line}, source, best);
}

// Modes 1..10 on the kTriedPartitions partitions whose subsets lie nearest their axes.
void tryTwoRegions(const Source& source, Candidate& best) {
  std::array<std::pair<float, int>, kPartitionCount> ranked;
  std::array<std::array<Line, 2>, kPartitionCount> lines;
  for (int p = 0; p < kPartitionCount; ++p) {
    const Fit first = fitSubset(source, 2, p, 0), second = fitSubset(source, 2, p, 1);
    ranked[p] = {first.residual + second.residual, p};
    lines[p] = {first.line, second.line};
  }
  std::partial_sort(ranked.begin(), ranked.begin() + kTriedPartitions, ranked.end());
  for (int r = 0; r < kTriedPartitions; ++r)
    for (int number = 1; number <= 10 && best.error > 0; ++number)
      tryMode(kModes[number - 1], ranked[r].second, lines[ranked[r].second], source, best);
}

// Runs one stage of the mode search and polishes its result when the stage found a better
// block: so each mode set's error is at most that of the sets it contains.
template <class Stage>
void runStage(const Source& source, Candidate& best, const Stage& stage) {
  const int64_t before = best.error;
  stage();
  if (best.error < before) polish(source, best);
}

}  // namespace

float bc6hClampInput(float value) {
  if (!(value > 0.0f)) return 0.0f;  // NaN, zeros and negatives
  return std::min(value, kBc6hMaxValue);
}

Bc6hBlock encodeBc6hBlock(const Bc6hTexels& texels, Bc6hModeSet modes) {
  const Source source = prepare(texels);
  Candidate best;
  runStage(source, best, [&] { tryOneRegion(source, 11, 11, best); });
  if (modes != Bc6hModeSet::kMode11)
    runStage(source, best, [&] { tryOneRegion(source, 12, 14, best); });
  if (modes == Bc6hModeSet::kAll && best.error > kTwoRegionMinError)
    runStage(source, best, [&] { tryTwoRegions(source, best); });
  return pack(best);
}

}  // namespace rdm
