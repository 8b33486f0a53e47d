// What an atlas was lit by (docs/spec.md section 4, index.json "lighting"): one digest per
// part of the scene that changes the baked light, so a viewer given another scene can name
// what differs (an atlas baked before a 10x sun or a palette change) instead of showing it.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "rdm/scene/scene.h"

namespace rdm {

// Part name -> XXH3 hex of its canonical JSON. Parts: "geometry" (size, blocks, placements),
// "palette", "sun", "sky", "emission_scale", "ambient", "bake" (the bake settings but the
// face light's spp, which face_light.bin's own digest covers). Cameras are not lighting.
using LightingFingerprint = std::map<std::string, std::string>;

// `settings` are the bake's (a CLI flag or a request may differ from the scene's "bake").
LightingFingerprint lightingFingerprint(const Scene& scene, const BakeSettings& settings);

// The parts whose digests differ, in the order above; a part one side lacks counts as
// differing. Either side empty (an atlas written before fingerprints): nothing is known, {}.
std::vector<std::string> lightingDifferences(const LightingFingerprint& baked,
                                             const LightingFingerprint& scene);

}  // namespace rdm
