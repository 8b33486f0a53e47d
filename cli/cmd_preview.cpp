#include <algorithm>
#include <cmath>
#include <cstdio>

#include "args.h"
#include "commands.h"
#include "rdm/exr_io.h"
#include "rdm/flip.h"
#include "rdm/png_io.h"

namespace rdm::cli {

// `rdm preview IN.exr -o OUT.png [--exposure E]`: Reinhard + sRGB view of an HDR image
// (an atlas, a single RDM or a render); `--depth` shows the Z channel instead.
int cmdPreview(const Args& args) {
  ArgParser parser({"-o", "--output", "--exposure"}, {"--help", "--depth"});
  std::string e = parser.parse(args);
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (!e.empty() || parser.flag("--help") || !out || parser.positionals().size() != 1) {
    std::fprintf(stderr, "%susage: rdm preview IN.exr -o OUT.png [--exposure E] [--depth]\n",
                 e.empty() ? "" : ("rdm preview: " + e + "\n").c_str());
    return parser.flag("--help") ? 0 : 2;
  }
  std::string error;
  const double exposure = parser.number("--exposure", error).value_or(0.0);
  if (!error.empty()) return std::fprintf(stderr, "rdm preview: %s\n", error.c_str()), 2;
  const bool depth = parser.flag("--depth");
  auto image = depth ? readExr(parser.positionals()[0], {"Z", "Z", "Z"})
                     : readExr(parser.positionals()[0], {"R", "G", "B"});
  if (!image) return std::fprintf(stderr, "rdm preview: %s\n", image.error().c_str()), 1;
  const float scale = float(std::exp2(exposure));
  for (float& v : image->pixels) v = depth ? (v >= 1e4f ? 0.0f : v / (1.0f + v)) : v * scale;
  Image mapped = depth ? *image : tonemapReinhardSrgb(*image);
  std::vector<uint8_t> bytes(mapped.pixels.size());
  for (size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = uint8_t(std::lround(std::clamp(mapped.pixels[i], 0.0f, 1.0f) * 255.0f));
  if (Status s = writePng(*out, mapped.width, mapped.height, 3, bytes); !s) {
    return std::fprintf(stderr, "rdm preview: %s\n", s.message().c_str()), 1;
  }
  return 0;
}

}  // namespace rdm::cli
