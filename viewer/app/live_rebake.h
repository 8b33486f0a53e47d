// Live incremental rebakes (`--server URL`): uploads the scene to the bake daemon, and after
// each edit PATCHes the changed slots, submits a fast incremental bake and, when it is done,
// downloads the new atlas into the renderer. Work runs on a background thread; the window
// polls for finished atlases.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "atlas_texture.h"
#include "rdm/scene.h"
#include "rdm/status.h"

namespace rdm::viewer {

class LiveRebake {
 public:
  static Expected<std::unique_ptr<LiveRebake>> connect(const std::string& url, const Scene& scene);
  ~LiveRebake();
  // Requests a rebake of `scene` (replacing any queued request).
  void requestRebake(const Scene& scene);
  // A finished atlas, once per bake.
  std::optional<LoadedAtlas> takeAtlas();
  std::string statusLine();

 private:
  struct Impl;
  explicit LiveRebake(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rdm::viewer
