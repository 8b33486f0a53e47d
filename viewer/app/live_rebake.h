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
#include <vector>

#include "atlas_texture.h"
#include "rdm/scene.h"
#include "rdm/status.h"

namespace rdm::viewer {

// What a finished bake brings: the whole atlas, or (for an incremental bake whose pages
// kept their sizes) the new layout plus the rects of the RDMs re-baked or moved since the
// previous bake, fetched one RDM at a time through `/delta` (SPEC section 8).
struct LiveAtlas {
  LoadedAtlas atlas;  // layout always; pages only when !is_delta
  bool is_delta = false;
  std::vector<AtlasRectUpdate> updates;
  std::string job;  // the daemon's job id
};

class LiveRebake {
 public:
  static Expected<std::unique_ptr<LiveRebake>> connect(const std::string& url, const Scene& scene);
  ~LiveRebake();
  // Requests a rebake of `scene` (replacing any queued request).
  void requestRebake(const Scene& scene);
  // A finished atlas or delta, once per bake.
  std::optional<LiveAtlas> takeAtlas();
  std::string statusLine();

 private:
  struct Impl;
  explicit LiveRebake(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rdm::viewer
