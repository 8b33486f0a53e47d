// Atlas deltas (docs/spec.md, "Atlas deltas"): what changed between the atlas a client holds
// and a pass of a job, with every changed rect's texels, in one message. The daemon builds
// and encodes them; the viewer decodes and uploads them into its atlas texture.
//
// Wire layout (all integers little-endian):
//   8 bytes  magic "RDMDLT02"
//   u32      header length H
//   H bytes  header JSON: {"job", "from", "pass", "passes", "final", "settings": {...},
//            "index": <the job's index.json object>, "rects": [{"slot", "level", "size",
//            "faces", "texel_size"}], "removed": [same fields but texel_size]}
//            (entries as rdm/atlas_json.h writes them)
//   then per rect, in header order, per stored face in face order: s x s texels
//   (s = texel_size <= size; a preview's RDMs are smaller), row-major, RGBZ float32
//   (16 bytes each)
#pragma once

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "rdm/atlas/atlas.h"
#include "rdm/base/status.h"
#include "rdm/image/image.h"
#include "rdm/scene/scene.h"

namespace rdm {

using RdmKey = std::tuple<int, int, int, int>;  // slot i, j, k and level
RdmKey rdmKey(const RdmId& id);

// A job's atlas as a client sees it: the layout and, per RDM, the job that baked its texels.
struct AtlasView {
  AtlasLayout layout;
  std::map<RdmKey, std::string> origin;
};

// Which entries of `now` a client holding `old` must (re)write: new RDMs, RDMs whose origin
// or tiles changed, and `old` entries no RDM of `now` has.
struct DeltaSelection {
  std::vector<AtlasEntry> rects;    // entries of now.layout
  std::vector<AtlasEntry> removed;  // entries of old.layout
};
DeltaSelection selectDelta(const AtlasView& old, const AtlasView& now);
// The pages of both layouts have the same sizes, so a client can patch in place.
bool samePages(const AtlasLayout& a, const AtlasLayout& b);
// Every page of `old` keeps its index and fits inside `now`'s (pages were only added or
// grew, as packIncremental does), so a client grows its texture and then patches it.
bool pagesGrow(const AtlasLayout& old, const AtlasLayout& now);

struct DeltaRect {
  AtlasEntry entry;
  // RGBZ, 2s x 3s with s <= entry.id.size when encoding (only stored faces travel); decoded
  // rects are always expanded to 2S x 3S (rdm::expandRdmImage), unstored faces 0, so a
  // client writes each stored face into its tile as it is.
  Image texels;
};

struct AtlasDelta {
  std::string job, from;
  int pass = 0, passes = 1;
  bool final = true;      // the job's last pass: the job's own settings
  BakeSettings settings;  // of this pass
  AtlasLayout layout;     // the job's whole layout
  std::vector<DeltaRect> rects;
  std::vector<AtlasEntry> removed;
};

std::string encodeAtlasDelta(const AtlasDelta& delta);
// Refuses (kInvalidInput, naming the part) anything that is not exactly a well-formed delta.
Expected<AtlasDelta> decodeAtlasDelta(const std::string& bytes);

constexpr const char* kAtlasDeltaMediaType = "application/x-rdm-delta";

}  // namespace rdm
