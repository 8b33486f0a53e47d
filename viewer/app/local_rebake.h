// Rebakes without a daemon (docs/viewer.md, "Baking without a daemon"): the core's
// IncrementalBaker on a worker thread, handing out the same progressive deltas as the daemon.
#pragma once

#include <memory>

#include "live_rebake.h"

namespace rdm::viewer {

class LocalRebake : public Rebaker {
 public:
  explicit LocalRebake(BakeMode mode = BakeMode::kExact);
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
