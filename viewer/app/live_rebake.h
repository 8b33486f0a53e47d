// Live incremental rebakes (`--server URL`, docs/viewer.md "Live rebakes"): uploads the scene
// to the bake daemon and bakes it whole once; after each edit PATCHes the scene
// (makeScenePatch), submits a progressive incremental bake and, as each pass is published,
// fetches its changed rects in one request (delta.bin). Work runs on a background thread; the
// window polls for finished updates and for the state to show.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "atlas_texture.h"
#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/rebake_selection.h"
#include "rdm/base/status.h"
#include "rdm/scene/scene.h"

namespace rdm::viewer {

class Renderer;

// What a published pass brings: the whole atlas (the first bake, or when no delta chains),
// or the new layout plus the rects re-baked or moved since the viewer's last converged job.
struct LiveAtlas {
  LoadedAtlas atlas;  // layout always; pages only when !is_delta
  bool is_delta = false;
  std::vector<AtlasRectUpdate> updates;
  std::string job;  // the daemon's job id
  int pass = 0, passes = 1;
  bool final = true;                      // the job's own settings; later edits start from here
  std::vector<glm::ivec3> preview_slots;  // slots whose RDMs this update holds at preview quality
  std::chrono::steady_clock::time_point received;  // when it was decoded, ready to upload
  std::optional<FaceLight> face_light;             // with a whole atlas of a job that baked one
};

// Puts `update` on `renderer`: its rects or whole atlas (whose pages it moves out, keeping the
// layout), and its face light when it has one.
Status applyLiveAtlas(Renderer& renderer, LiveAtlas& update);

// What the panel shows; a snapshot, safe to copy.
struct LiveState {
  bool connected = true;
  bool busy = false;    // a bake is queued or running
  bool failed = false;  // the last rebake failed (message says why); cleared by the next one
  std::string job, mode, message;
  int pass = 0, passes = 1;  // the pass being baked
  double fraction = 0.0;
  std::optional<double> eta_seconds;
  // Phase of the running job: "rdms", "face_light", ... (the daemon's progress.phase), or empty.
  std::string phase;
  // Slots where the scene asked for differs from the one the converged atlas was baked for:
  // edits whose final pass has not landed. Outlined.
  std::vector<glm::ivec3> stale_slots;
  int preview_rdms =
      0;  // RDMs shown at preview quality until the final pass; counted, not outlined
};

struct LiveOptions {
  BakeMode mode = BakeMode::kExact;  // of the incremental jobs
  std::string token;
  // Samples per face of the face light every job bakes (docs/api.md): -1 the scene's
  // bake.face_light_spp, 0 none. Whole atlases of a job with face light bring it, and edits
  // update it in the renderer as in-process.
  int face_light_spp = -1;
};

// The update a delta brings: rects in place, or (`whole`) pages assembled from its rects.
LiveAtlas liveAtlasOf(AtlasDelta delta, bool whole);

// Where rebakes come from: the daemon (LiveRebake) or the core in-process (LocalRebake).
class Rebaker {
 public:
  virtual ~Rebaker() = default;
  // Requests a rebake of `scene` (replacing any queued request).
  virtual void requestRebake(const Scene& scene) = 0;
  // Cancels the running bake; the viewer keeps (or gets back) the last converged atlas.
  virtual void requestCancel() = 0;
  // The published updates, in order, each once.
  virtual std::optional<LiveAtlas> takeAtlas() = 0;
  virtual LiveState state() = 0;
  std::string statusLine() { return state().message; }
};

class LiveRebake : public Rebaker {
 public:
  static Expected<std::unique_ptr<LiveRebake>> connect(const std::string& url, const Scene& scene,
                                                       const LiveOptions& options = {});
  ~LiveRebake() override;
  void requestRebake(const Scene& scene) override;
  void requestCancel() override;
  std::optional<LiveAtlas> takeAtlas() override;
  LiveState state() override;

 private:
  struct Impl;
  explicit LiveRebake(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rdm::viewer
