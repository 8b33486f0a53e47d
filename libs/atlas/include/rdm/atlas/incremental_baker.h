// In-process incremental rebakes (docs/viewer.md, "Baking without a daemon"): the daemon's
// rebake selection and progressive passes applied to successive versions of a scene held in
// memory, each pass handed out as an AtlasDelta. The first bake, and any bake whose atlas
// pages change size, hands out every rect. Results are bit-identical to the daemon's and to
// `rdm bake` for the same scene and settings.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/rebake_selection.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/status.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct IncrementalBakeOptions {
  BakeMode mode = BakeMode::kExact;
  int threads = 0;
  const std::atomic<bool>* cancel = nullptr;
  std::function<void(int pass, int passes, const BakeProgress&)> on_progress;
};

class IncrementalBaker {
 public:
  // Bakes `scene` against the last bake; `on_pass` receives each pass in order. A cancelled
  // bake hands out one more delta restoring the previous atlas' rects and keeps the previous
  // state; it returns kCancelled.
  Status bake(const Scene& scene, const IncrementalBakeOptions& options,
              const std::function<void(AtlasDelta)>& on_pass);
  bool hasBase() const { return scene_.has_value(); }
  // Takes the atlas `rdm bake` wrote to `dir` for `scene` as the last bake, so the next bake
  // re-bakes only what changed. Refused (and nothing kept) unless the atlas holds exactly the
  // scene's RDMs, lit as `scene` lights them with its bake settings, and `dir` has the slot
  // sets (rdms.bin) of every RDM. A half atlas seeds the texels it stores (rounded).
  Status seedFromAtlas(const Scene& scene, const std::string& dir);

 private:
  AtlasDelta deltaOf(const AtlasLayout& layout, const std::vector<RdmId>& ids,
                     const std::map<RdmKey, Image>& images) const;

  std::optional<Scene> scene_;
  std::unique_ptr<VoxelWorld> world_;
  AtlasLayout layout_;
  std::map<RdmKey, Image> images_;
  std::map<RdmKey, RdmRecord> records_;
  int bakes_ = 0;
};

}  // namespace rdm
