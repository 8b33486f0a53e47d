// The cross-block denoiser (docs/denoise.md, docs/spec.md section 3.3): a joint bilateral
// filter over each face's hemisphere map and the same face of the four slots beside it in
// the face's plane. Those faces use the same frame, so their texel (i, j) looks in the same
// world direction from an origin one world unit away; their texels enter the filter like the
// face's own, shifted by that unit's parallax. Each RDM is filtered with the same weights its
// neighbours use for it, so neighbouring blocks come closer together and no block border is
// treated differently from a texel step: no seam is made.
//
// Measured in docs/denoise.md.
//
// Guides: the depth Z (no tap across a depth step) and the standard error of every texel (a
// colour difference counts in units of the pair's error, so edges the noise cannot explain
// stay, and texels whose relative error is below a floor are left as they are). Z is kept;
// the standard error becomes that of the weighted mean, so noise.exr reports the result.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/bake/rdm_list.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/base/status.h"
#include "shared/rdm_denoise.h"

namespace rdm {

struct DenoiseSettings {
  int radius = 2;              // texels each side of the centre: a (2 radius + 1)^2 window
  float spatial_sigma = 1.5f;  // texels (a neighbour slot's parallax adds to the distance)
  float color_sigma = 1.0f;    // a colour difference, in units of the pair's standard error
  float depth_sigma = 0.05f;   // a depth difference, relative to the larger depth
  // Texels whose relative standard error (noise.exr's E) is below this are left as they are.
  float min_relative_error = 0.005f;
  bool across_slots = true;  // false: each face's own map only (the per-tile filter)
  // The bake's estimator was prefiltered (section 3.1): levels 1 to 7 are derived from each
  // face's map by kernels wider than the window, so their neighbouring texels share their
  // noise. With derived_window false those levels take only the other blocks' texel in the
  // same direction, which keeps the atlas nearest a many-sample bake (island, 1 spp: relative
  // error 0.0231 against 0.0234); with it true (the default) they take the window as level 0
  // and a naive bake's levels do, which the viewer's image prefers (island LDR-FLIP 0.01033
  // against 0.01061; docs/denoise.md).
  bool prefiltered = true;
  bool derived_window = true;
};

struct DenoiseStats {
  size_t rdms = 0;
  size_t texels = 0;    // texels of stored faces
  size_t filtered = 0;  // of them, those above min_relative_error
  double seconds = 0.0;
  double cpu_seconds = 0.0;
  // Luminance of every stored texel's value and of its standard error, summed, before and
  // after: their ratio is the relative error of the whole bake, which a few black texels
  // with an error (whose own ratio is unbounded) do not dominate.
  double value_before = 0.0, error_before = 0.0, value_after = 0.0, error_after = 0.0;
  double relativeErrorBefore() const { return value_before > 0 ? error_before / value_before : 0; }
  double relativeErrorAfter() const { return value_after > 0 ? error_after / value_after : 0; }
  void add(const DenoiseStats& part);
};

// bake_report.json's "denoise" object: the settings, the counts, the time and the mean
// relative standard error before and after (docs/api.md).
nlohmann::json denoiseReportJson(const DenoiseSettings& settings, const DenoiseStats& stats);

// The face-plane neighbours of an RDM, in order -a1, +a1, -a2, +a2 (a1 < a2 the two world
// axes other than the face's normal axis); null where there is none at the same level and
// size. Face f of `center` uses index set planeNeighbourSet(f).
using PlaneNeighbours = std::array<const RdmData*, 4>;
// The slots beside `slot` in the plane of faces along `axis` (0 x, 1 y, 2 z), in the order
// above.
std::array<glm::ivec3, 4> planeNeighbourSlots(const glm::ivec3& slot, int axis);

// `center` filtered; neighbours[axis] holds the plane neighbours of faces along that axis.
// Adds to stats' counts and errors.
RdmData denoiseRdm(const RdmData& center, const std::array<PlaneNeighbours, 3>& neighbours,
                   const DenoiseSettings& settings, DenoiseStats& stats);

// The parts every backend shares (shaders/shared/rdm_denoise.h holds the per-texel filter).
// Whether `rdm` carries a standard error per texel (one copied from a store does not).
bool hasStandardError(const RdmData& rdm);
// Face f of `rdm` as the filter reads it: S x S texels, row-major, with their guides.
std::vector<shared::DenoiseTexel> denoiseFaceTexels(const RdmData& rdm, int f);
// The faces face f of `center` is filtered with, in the filter's order: its own, then each
// plane neighbour that stores face f at the same size with its standard error (none when
// !across_slots).
std::vector<const RdmData*> denoiseFaceSet(const RdmData& center, int f,
                                           const PlaneNeighbours& plane,
                                           const DenoiseSettings& settings);
// The window radius at `center`'s level (DenoiseSettings::prefiltered).
int denoiseWindow(const RdmData& center, const DenoiseSettings& settings);
shared::DenoiseParams denoiseParams(const DenoiseSettings& settings);
// Writes texel (i, j) of face f of `out` as `result` and counts it against `read` (the texel
// as baked) in `stats`; `filtered`: whether the filter ran on it.
void storeDenoisedTexel(RdmData& out, int f, int i, int j, const shared::DenoiseTexel& read,
                        const shared::DenoiseTexel& result, bool filtered, DenoiseStats& stats);

// One RDM to filter and its plane neighbours, as denoiseRdm takes them.
struct DenoiseInput {
  const RdmData* center = nullptr;
  std::array<PlaneNeighbours, 3> neighbours{};
};
// A device that filters batches of RDMs (rdm/vulkan/vulkan_denoise.h): out[k] is what
// denoiseRdm gives for batch[k], up to the device's float rounding.
class DenoiseDevice {
 public:
  virtual ~DenoiseDevice() = default;
  [[nodiscard]] virtual Status denoise(const std::vector<DenoiseInput>& batch,
                                       const DenoiseSettings& settings, std::vector<RdmData>& out,
                                       DenoiseStats& stats) = 0;
  virtual size_t batchRdms() const { return 16; }  // RDMs handed over at once
};

// Every RDM of `rdms` filtered and appended to `out` in the order of `rdms`, each with its
// neighbours taken from `rdms` or else from `context` (an incremental job's kept RDMs; may be
// null). Holds the RDMs in flight and their neighbours, not the source. `threads` as
// ParallelOptions (reads, and the filter on the CPU); `device`: filter there instead (null:
// the CPU). Fails on the first read or device error (the message names it); stats are the
// run's.
[[nodiscard]] Status denoiseRdms(const RdmSource& rdms, const RdmSource* context, RdmSpill& out,
                                 const DenoiseSettings& settings, int threads, DenoiseStats& stats,
                                 DenoiseDevice* device = nullptr);

}  // namespace rdm
