// FLIP as in notes/formulas.md section 4.7. Filters are separable (the blue-yellow CSF is a
// sum of two separable Gaussians) and applied as correlations with replicated borders; the
// edge detector's sign is irrelevant because only gradient magnitudes are compared.
#include "rdm/image/flip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "rdm/base/check.h"
#include "rdm/base/parallel.h"
#include "rdm/image/tonemap.h"

namespace rdm {
namespace {

constexpr double kColorExponent = 0.7;     // q_c
constexpr double kFeatureExponent = 0.5;   // q_f
constexpr double kRedistributeCut = 0.4;   // p_c
constexpr double kRedistributeTop = 0.95;  // p_t
constexpr double kFeatureWidthDegrees = 0.082;
constexpr double kLabDelta = 6.0 / 29.0;

using Vec3 = std::array<double, 3>;
using Mat3 = std::array<Vec3, 3>;

constexpr Mat3 kRgbToXyz = {{{10135552.0 / 24577794, 8788810.0 / 24577794, 4435075.0 / 24577794},
                             {2613072.0 / 12288897, 8788810.0 / 12288897, 887015.0 / 12288897},
                             {1425312.0 / 73733382, 8788810.0 / 73733382, 70074185.0 / 73733382}}};
constexpr Vec3 kWhite = {0.950428545, 1.0, 1.088900371};

constexpr Mat3 invert(const Mat3& m) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      // Cofactor of m[j][i] (cyclic index form gives the sign for free).
      int j1 = (j + 1) % 3, j2 = (j + 2) % 3, i1 = (i + 1) % 3, i2 = (i + 2) % 3;
      r[i][j] = m[j1][i1] * m[j2][i2] - m[j1][i2] * m[j2][i1];
    }
  }
  double det = m[0][0] * r[0][0] + m[0][1] * r[1][0] + m[0][2] * r[2][0];
  for (auto& row : r)
    for (double& v : row) v /= det;
  return r;
}
constexpr Mat3 kXyzToRgb = invert(kRgbToXyz);

Vec3 mul(const Mat3& m, const Vec3& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
          m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

// Clamps to [0, 1]; NaN -> 0.
float clamp01(float v) {
  return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
}

// One channel, row-major.
struct Plane {
  int width = 0;
  int height = 0;
  std::vector<float> v;
  Plane(int w, int h) : width(w), height(h), v(size_t(w) * h, 0.0f) {}
};

// Odd-sized 1-D kernel; element `radius` is the centre.
using Kernel = std::vector<float>;

Plane correlateRows(const Plane& in, const Kernel& k) {
  int r = int(k.size() / 2), w = in.width;
  Plane out(in.width, in.height);
  std::vector<float> padded(size_t(w) + 2 * r);
  for (int y = 0; y < in.height; ++y) {
    const float* src = &in.v[size_t(y) * w];
    for (int i = 0; i < w + 2 * r; ++i) padded[i] = src[std::clamp(i - r, 0, w - 1)];
    float* dst = &out.v[size_t(y) * w];
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (size_t j = 0; j < k.size(); ++j) sum += k[j] * padded[x + j];
      dst[x] = sum;
    }
  }
  return out;
}

Plane correlateColumns(const Plane& in, const Kernel& k) {
  int r = int(k.size() / 2), w = in.width, h = in.height;
  Plane out(w, h);
  for (int y = 0; y < h; ++y) {
    float* dst = &out.v[size_t(y) * w];
    for (int j = 0; j < int(k.size()); ++j) {
      const float* src = &in.v[size_t(std::clamp(y + j - r, 0, h - 1)) * w];
      float kj = k[j];
      for (int x = 0; x < w; ++x) dst[x] += kj * src[x];
    }
  }
  return out;
}

Plane separable(const Plane& in, const Kernel& rows, const Kernel& columns) {
  return correlateColumns(correlateRows(in, rows), columns);
}

// CSF: s(r) = a1 sqrt(pi/b1) exp(-pi^2 r^2 / b1) + a2 sqrt(pi/b2) exp(-pi^2 r^2 / b2), r in
// degrees; the 2-D kernel is normalised to sum 1, so it equals
// weight[0] g1(x) g1(y) + weight[1] g2(x) g2(y) with g1, g2 normalised 1-D Gaussians.
struct CsfParams {
  double a1, b1, a2, b2;
};
constexpr CsfParams kCsfAchromatic = {1.0, 0.0047, 0.0, 1e-5};
constexpr CsfParams kCsfRedGreen = {1.0, 0.0053, 0.0, 1e-5};
constexpr CsfParams kCsfBlueYellow = {34.1, 0.04, 13.5, 0.025};

struct CsfFilter {
  std::array<Kernel, 2> gaussian;
  std::array<float, 2> weight;
};

int csfRadius(double ppd) {
  double max_b = 0.0;
  for (const CsfParams& p : {kCsfAchromatic, kCsfRedGreen, kCsfBlueYellow})
    max_b = std::max({max_b, p.b1, p.b2});
  return int(std::ceil(3.0 * std::sqrt(max_b / (2.0 * std::numbers::pi * std::numbers::pi)) * ppd));
}

CsfFilter makeCsfFilter(const CsfParams& p, double ppd, int radius) {
  CsfFilter filter;
  std::array<double, 2> a = {p.a1, p.a2}, b = {p.b1, p.b2}, total{};
  for (int i = 0; i < 2; ++i) {
    double sum = 0.0;
    std::vector<double> g(2 * radius + 1);
    for (int x = -radius; x <= radius; ++x) {
      double deg = x / ppd;
      g[x + radius] = std::exp(-std::numbers::pi * std::numbers::pi * deg * deg / b[i]);
      sum += g[x + radius];
    }
    for (double v : g) filter.gaussian[i].push_back(float(v / sum));
    total[i] = a[i] * std::sqrt(std::numbers::pi / b[i]) * sum * sum;
  }
  for (int i = 0; i < 2; ++i) filter.weight[i] = float(total[i] / (total[0] + total[1]));
  return filter;
}

Plane applyCsf(const Plane& in, const CsfFilter& f) {
  Plane out = separable(in, f.gaussian[0], f.gaussian[0]);
  if (f.weight[1] == 0.0f) return out;
  Plane second = separable(in, f.gaussian[1], f.gaussian[1]);
  for (size_t i = 0; i < out.v.size(); ++i)
    out.v[i] = f.weight[0] * out.v[i] + f.weight[1] * second.v[i];
  return out;
}

// Feature kernels: x-factor (derivative or second derivative of a Gaussian, positive
// weights normalised to sum 1 and negative ones to -1) times a normalised Gaussian in y.
struct FeatureKernels {
  Kernel gaussian, edge, point;
};

Kernel normaliseSigned(const std::vector<double>& k) {
  double pos = 0.0, neg = 0.0;
  for (double v : k) (v > 0.0 ? pos : neg) += v;
  Kernel out;
  for (double v : k) out.push_back(float(v > 0.0 ? v / pos : (v < 0.0 ? -v / neg : 0.0)));
  return out;
}

FeatureKernels makeFeatureKernels(double ppd) {
  double sigma = 0.5 * kFeatureWidthDegrees * ppd;
  int radius = int(std::ceil(3.0 * sigma));
  std::vector<double> g, edge, point;
  for (int x = -radius; x <= radius; ++x) {
    double gx = std::exp(-double(x) * x / (2.0 * sigma * sigma));
    g.push_back(gx);
    edge.push_back(-x * gx);
    point.push_back((double(x) * x / (sigma * sigma) - 1.0) * gx);
  }
  return {normaliseSigned(g), normaliseSigned(edge), normaliseSigned(point)};
}

Vec3 linearRgbToHuntLab(const Vec3& rgb) {
  Vec3 xyz = mul(kRgbToXyz, rgb);
  Vec3 f;
  for (int i = 0; i < 3; ++i) {
    double t = xyz[i] / kWhite[i];
    constexpr double kCube = kLabDelta * kLabDelta * kLabDelta;
    f[i] = t > kCube ? std::cbrt(t) : t / (3.0 * kLabDelta * kLabDelta) + 4.0 / 29.0;
  }
  double l = 116.0 * f[1] - 16.0;
  return {l, 0.01 * l * 500.0 * (f[0] - f[1]), 0.01 * l * 200.0 * (f[1] - f[2])};
}

double hyab(const Vec3& p, const Vec3& q) {
  return std::abs(p[0] - q[0]) + std::hypot(p[1] - q[1], p[2] - q[2]);
}

// c_max = HyAB(Hunt(green), Hunt(blue))^q_c.
double maxColorError() {
  static const double c_max =
      std::pow(hyab(linearRgbToHuntLab({0.0, 1.0, 0.0}), linearRgbToHuntLab({0.0, 0.0, 1.0})),
               kColorExponent);
  return c_max;
}

// Per-image intermediate results: Hunt-adjusted L*a*b* of the CSF-filtered image and the
// edge / point feature magnitudes of its achromatic channel.
struct Perceived {
  Plane l, a, b, edge, point;
  Perceived(int w, int h) : l(w, h), a(w, h), b(w, h), edge(w, h), point(w, h) {}
};

void computeFeatures(const Plane& luma, const FeatureKernels& k, Perceived& out) {
  Plane rows_g = correlateRows(luma, k.gaussian);
  Plane edge_x = correlateColumns(correlateRows(luma, k.edge), k.gaussian);
  Plane edge_y = correlateColumns(rows_g, k.edge);
  Plane point_x = correlateColumns(correlateRows(luma, k.point), k.gaussian);
  Plane point_y = correlateColumns(rows_g, k.point);
  for (size_t i = 0; i < luma.v.size(); ++i) {
    out.edge.v[i] = std::hypot(edge_x.v[i], edge_y.v[i]);
    out.point.v[i] = std::hypot(point_x.v[i], point_y.v[i]);
  }
}

Perceived perceive(const Image& srgb, double ppd) {
  int w = srgb.width, h = srgb.height;
  Plane yy(w, h), cx(w, h), cz(w, h), luma(w, h);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    const float* p = &srgb.pixels[i * 3];
    Vec3 rgb = {srgbDecode(clamp01(p[0])), srgbDecode(clamp01(p[1])), srgbDecode(clamp01(p[2]))};
    Vec3 xyz = mul(kRgbToXyz, rgb);
    double x = xyz[0] / kWhite[0], y = xyz[1] / kWhite[1], z = xyz[2] / kWhite[2];
    yy.v[i] = float(116.0 * y - 16.0);
    cx.v[i] = float(500.0 * (x - y));
    cz.v[i] = float(200.0 * (y - z));
    luma.v[i] = (yy.v[i] + 16.0f) / 116.0f;
  }
  int radius = csfRadius(ppd);
  yy = applyCsf(yy, makeCsfFilter(kCsfAchromatic, ppd, radius));
  cx = applyCsf(cx, makeCsfFilter(kCsfRedGreen, ppd, radius));
  cz = applyCsf(cz, makeCsfFilter(kCsfBlueYellow, ppd, radius));
  Perceived out(w, h);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    double y = (yy.v[i] + 16.0) / 116.0;
    Vec3 xyz = {(cx.v[i] / 500.0 + y) * kWhite[0], y * kWhite[1],
                (y - cz.v[i] / 200.0) * kWhite[2]};
    Vec3 rgb = mul(kXyzToRgb, xyz);
    for (double& c : rgb) c = std::clamp(c, 0.0, 1.0);
    Vec3 lab = linearRgbToHuntLab(rgb);
    out.l.v[i] = float(lab[0]);
    out.a.v[i] = float(lab[1]);
    out.b.v[i] = float(lab[2]);
  }
  computeFeatures(luma, makeFeatureKernels(ppd), out);
  return out;
}

// Maps HyAB^q_c to [0, 1]: [0, p_c c_max) linearly onto [0, p_t), the rest onto [p_t, 1].
double redistributeColorError(double x) {
  double c_max = maxColorError(), cut = kRedistributeCut * c_max;
  double e = x < cut ? kRedistributeTop / cut * x
                     : kRedistributeTop + (x - cut) / (c_max - cut) * (1.0 - kRedistributeTop);
  return std::min(e, 1.0);
}

float flipPixel(const Perceived& ref, const Perceived& test, size_t i) {
  Vec3 p = {ref.l.v[i], ref.a.v[i], ref.b.v[i]}, q = {test.l.v[i], test.a.v[i], test.b.v[i]};
  double color = redistributeColorError(std::pow(hyab(p, q), kColorExponent));
  double feature_diff = std::max(std::abs(ref.edge.v[i] - test.edge.v[i]),
                                 std::abs(ref.point.v[i] - test.point.v[i]));
  double feature = std::min(1.0, std::pow(feature_diff / std::sqrt(2.0), kFeatureExponent));
  return float(std::pow(color, 1.0 - feature));
}

double meanOf(const Image& image) {
  double sum = 0.0;
  for (float v : image.pixels) sum += v;
  return image.pixels.empty() ? 0.0 : sum / double(image.pixels.size());
}

void checkPair(const Image& reference, const Image& test, double ppd) {
  RDM_CHECK(reference.width == test.width && reference.height == test.height);
  RDM_CHECK(reference.channels == 3 && test.channels == 3);
  RDM_CHECK(reference.pixels.size() == size_t(reference.width) * reference.height * 3);
  RDM_CHECK(test.pixels.size() == reference.pixels.size());
  RDM_CHECK(std::isfinite(ppd) && ppd > 0.0);
}

// ACES fit y = (k0 x^2 + k1 x + k2) / (k3 x^2 + k4 x + k5).
constexpr std::array<double, 6> kAces = {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0,
                                         0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};
constexpr double kExposureTarget = 0.85;  // t_max = t_min
constexpr double kMinLuminance = 1e-6;

double acesTonemap(double x) {
  if (!(x > 0.0)) return 0.0;
  if (std::isinf(x)) return 1.0;
  double y =
      (kAces[0] * x * x + kAces[1] * x + kAces[2]) / (kAces[3] * x * x + kAces[4] * x + kAces[5]);
  return std::clamp(y, 0.0, 1.0);
}

// Positive x with acesTonemap(x) == t.
double acesInverse(double t) {
  double c0 = kAces[0] - t * kAces[3], c1 = kAces[1] - t * kAces[4], c2 = kAces[2] - t * kAces[5];
  if (c0 == 0.0) return -c2 / c1;
  return (-c1 + std::sqrt(c1 * c1 - 4.0 * c0 * c2)) / (2.0 * c0);
}

// [start, stop] exposures (log2 scale factors) from the reference's max and median luminance.
std::array<double, 2> exposureRange(const Image& linear) {
  std::vector<double> lum(size_t(linear.width) * linear.height);
  for (size_t i = 0; i < lum.size(); ++i) {
    const float* p = &linear.pixels[i * 3];
    double y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    lum[i] = y > kMinLuminance ? std::min(y, 3.4e38) : kMinLuminance;  // NaN -> floor
  }
  double max_lum = *std::max_element(lum.begin(), lum.end());
  if (max_lum <= kMinLuminance) return {0.0, 0.0};  // black reference: exposure 0 only
  size_t mid = lum.size() / 2;
  std::nth_element(lum.begin(), lum.begin() + mid, lum.end());
  double median = lum[mid];
  if (lum.size() % 2 == 0)
    median = 0.5 * (median + *std::max_element(lum.begin(), lum.begin() + mid));
  double x = acesInverse(kExposureTarget);
  return {std::log2(x / max_lum), std::log2(x / median)};
}

Image acesSrgb(const Image& linear, double scale) {
  Image out(linear.width, linear.height, linear.channels);
  for (size_t i = 0; i < out.pixels.size(); ++i)
    out.pixels[i] = srgbEncode(float(acesTonemap(scale * linear.pixels[i])));
  return out;
}

}  // namespace

FlipResult computeLdrFlip(const Image& reference_srgb, const Image& test_srgb,
                          double pixels_per_degree) {
  checkPair(reference_srgb, test_srgb, pixels_per_degree);
  FlipResult result{Image(test_srgb.width, test_srgb.height, 1), 0.0};
  if (result.error_map.pixels.empty()) return result;
  std::optional<Perceived> perceived[2];  // reference, test: the two images at once
  ParallelOptions two;
  two.threads = 2;
  parallelFor(2, two, [&](size_t i) {
    perceived[i].emplace(perceive(i == 0 ? reference_srgb : test_srgb, pixels_per_degree));
    return true;
  });
  for (size_t i = 0; i < result.error_map.pixels.size(); ++i)
    result.error_map.pixels[i] = flipPixel(*perceived[0], *perceived[1], i);
  result.mean = meanOf(result.error_map);
  return result;
}

FlipResult computeHdrFlip(const Image& reference_linear, const Image& test_linear,
                          double pixels_per_degree) {
  checkPair(reference_linear, test_linear, pixels_per_degree);
  FlipResult result{Image(test_linear.width, test_linear.height, 1), 0.0};
  if (result.error_map.pixels.empty()) return result;
  auto [start, stop] = exposureRange(reference_linear);
  int count = std::max(2, int(std::ceil(stop - start)));
  double step = (stop - start) / (count - 1);
  for (int e = 0; e < count; ++e) {
    double scale = std::exp2(start + e * step);
    FlipResult ldr = computeLdrFlip(acesSrgb(reference_linear, scale), acesSrgb(test_linear, scale),
                                    pixels_per_degree);
    for (size_t i = 0; i < ldr.error_map.pixels.size(); ++i)
      result.error_map.pixels[i] = std::max(result.error_map.pixels[i], ldr.error_map.pixels[i]);
  }
  result.mean = meanOf(result.error_map);
  return result;
}

namespace {

// matplotlib's magma at t = i / 16.
// clang-format off
constexpr std::array<std::array<float, 3>, 17> kMagma = {{
    {0.001462f, 0.000466f, 0.013866f}, {0.039608f, 0.031090f, 0.133515f},
    {0.113094f, 0.065492f, 0.276784f}, {0.211718f, 0.061992f, 0.418647f},
    {0.316654f, 0.071690f, 0.485380f}, {0.414709f, 0.110431f, 0.504662f},
    {0.512831f, 0.148179f, 0.507648f}, {0.613617f, 0.181811f, 0.498536f},
    {0.716387f, 0.214982f, 0.475290f}, {0.816914f, 0.255895f, 0.436461f},
    {0.904281f, 0.319610f, 0.388137f}, {0.960949f, 0.418323f, 0.359630f},
    {0.986700f, 0.535582f, 0.382210f}, {0.996096f, 0.653659f, 0.446213f},
    {0.996898f, 0.769591f, 0.534892f}, {0.992440f, 0.884330f, 0.640099f},
    {0.987053f, 0.991438f, 0.749504f},
}};
// clang-format on

std::array<uint8_t, 3> magma(float t) {
  float pos = clamp01(t) * 16.0f;
  int i = std::min(15, int(pos));
  float f = pos - float(i);
  std::array<uint8_t, 3> rgb;
  for (int c = 0; c < 3; ++c) {
    float v = kMagma[i][c] + f * (kMagma[i + 1][c] - kMagma[i][c]);
    rgb[c] = uint8_t(std::lround(clamp01(v) * 255.0f));
  }
  return rgb;
}

// 3x5 bitmap glyphs: one byte per row, top first, bit (width - 1 - column) set = ink.
struct Glyph {
  char c;
  int width;
  std::array<uint8_t, 5> rows;
};
constexpr Glyph kGlyphs[] = {{'0', 3, {7, 5, 5, 5, 7}}, {'1', 3, {2, 6, 2, 2, 7}},
                             {'2', 3, {7, 1, 7, 4, 7}}, {'5', 3, {7, 4, 7, 1, 7}},
                             {'7', 3, {7, 1, 1, 2, 2}}, {'.', 1, {0, 0, 0, 0, 1}}};

const Glyph& glyph(char c) {
  for (const Glyph& g : kGlyphs)
    if (g.c == c) return g;
  RDM_CHECK(false);
  return kGlyphs[0];
}

constexpr uint8_t kLegendBackground = 24;
constexpr uint8_t kLegendInk = 235;

void fillRect(Image8& image, int x0, int y0, int w, int h, std::array<uint8_t, 3> rgb) {
  for (int y = std::max(0, y0); y < std::min(image.height, y0 + h); ++y)
    for (int x = std::max(0, x0); x < std::min(image.width, x0 + w); ++x)
      for (int c = 0; c < 3; ++c) image.pixels[(size_t(y) * image.width + x) * 3 + c] = rgb[c];
}

int textWidth(const std::string& text, int scale) {
  int w = 0;
  for (char c : text) w += (glyph(c).width + 1) * scale;
  return w - scale;
}

// Draws `text` with its top-left corner at (x0, y0); pixels outside the image are dropped.
void drawText(Image8& image, const std::string& text, int x0, int y0, int scale) {
  std::array<uint8_t, 3> ink = {kLegendInk, kLegendInk, kLegendInk};
  for (char c : text) {
    const Glyph& g = glyph(c);
    for (int row = 0; row < 5; ++row)
      for (int col = 0; col < g.width; ++col)
        if (g.rows[row] >> (g.width - 1 - col) & 1)
          fillRect(image, x0 + col * scale, y0 + row * scale, scale, scale, ink);
    x0 += (g.width + 1) * scale;
  }
}

}  // namespace

Image8 magmaColorMap(const Image& error_map) {
  RDM_CHECK(error_map.channels == 1);
  Image8 out{error_map.width, error_map.height, 3, {}};
  out.pixels.reserve(error_map.pixels.size() * 3);
  for (float v : error_map.pixels)
    for (uint8_t c : magma(v)) out.pixels.push_back(c);
  return out;
}

Image8 appendColorLegend(const Image8& map) {
  RDM_CHECK(map.channels == 3 && map.pixels.size() == size_t(map.width) * map.height * 3);
  int s = std::max(1, map.width / 400);  // pixel scale of strip, ticks and glyphs
  int gap = 4 * s, strip = 10 * s, tick = 3 * s, label = 5 * s;
  int legend_height = gap + strip + tick + s + label + 3 * s;
  Image8 out{map.width, map.height + legend_height, 3, map.pixels};
  out.pixels.resize(size_t(out.width) * out.height * 3, kLegendBackground);
  if (map.width < 2) return out;
  int margin = map.width >= 64 ? std::max(2, map.width / 32) : 0;
  int x0 = margin, x1 = map.width - 1 - margin, strip_top = map.height + gap;
  for (int x = x0; x <= x1; ++x)
    fillRect(out, x, strip_top, 1, strip, magma(float(x - x0) / float(x1 - x0)));
  const char* labels[] = {"0", "0.25", "0.5", "0.75", "1"};
  bool room_for_labels = (x1 - x0) / 4 > textWidth("0.75", s) + 2 * s;
  for (int i = 0; i < 5; ++i) {
    int tx = x0 + int(std::lround(0.25 * i * (x1 - x0)));
    int tick_x = std::clamp(tx - s / 2, 0, map.width - s);
    fillRect(out, tick_x, strip_top + strip, s, tick, {kLegendInk, kLegendInk, kLegendInk});
    if (!room_for_labels) continue;
    int w = textWidth(labels[i], s);
    drawText(out, labels[i], std::clamp(tx - w / 2, 0, map.width - w), strip_top + strip + tick + s,
             s);
  }
  return out;
}

}  // namespace rdm
