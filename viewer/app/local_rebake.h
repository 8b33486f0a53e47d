// Rebakes without a daemon (docs/viewer.md, "Baking without a daemon"): the core's
// IncrementalBaker on a worker thread, handing out the same progressive deltas as the daemon.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "live_rebake.h"

namespace rdm::viewer {

// An atlas `rdm bake` wrote for `scene` (the scene as loaded, before any edit): the first
// rebake starts from it instead of baking everything (IncrementalBaker::seedFromAtlas).
struct LocalSeed {
  Scene scene;
  std::string atlas_dir;
};

class LocalRebake : public Rebaker {
 public:
  explicit LocalRebake(BakeMode mode = BakeMode::kExact, std::optional<LocalSeed> seed = {});
  ~LocalRebake() override;
  void requestRebake(const Scene& scene) override;
  void requestCancel() override;
  std::optional<LiveAtlas> takeAtlas() override;
  LiveState state() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rdm::viewer
