// rdm-viewer [--server URL] --offscreen OUT.png --edit EDIT: the live path without a window.
// Bakes the scene whole (on the daemon, or in-process without --server; in-process with
// --atlas the atlas is the base instead), renders it, applies one edit, then renders each
// update as it arrives and reports when the first one and the converged one were on screen.
#include <chrono>
#include <cstdio>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "edit_command.h"
#include "live_rebake.h"
#include "local_rebake.h"
#include "rdm/base/file_util.h"
#include "run_modes.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kTimeoutSeconds = 600.0;

struct EditTimings {
  double first = -1.0, converged = -1.0;                    // seconds after the edit, on screen
  double first_received = -1.0, converged_received = -1.0;  // the delta decoded, before upload
  double geometry = -1.0;                                   // the edited geometry's first frame
  size_t first_tiles = 0, final_tiles = 0;
  int passes = 0;
  std::string job;
};

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Applies every waiting update and renders once, at full resolution once the final update is
// in and at `live_divisor` before (as the window does); returns the updates applied.
Expected<std::vector<LiveAtlas>> showUpdates(Rebaker& live, Renderer& r, const Camera& camera,
                                             uint32_t terms, int live_divisor) {
  std::vector<LiveAtlas> shown;
  bool final = false;
  while (auto update = live.takeAtlas()) {
    if (Status s = applyLiveAtlas(r, *update); !s.ok()) return s;
    final = final || update->final;
    shown.push_back(std::move(*update));
  }
  if (!shown.empty()) {
    r.setResolutionDivisor(final ? 1 : live_divisor);
    auto frame = r.renderFrame(camera, terms);
    if (!frame) return frame.status();
  }
  return shown;
}

// Waits until an update with `final` set is on screen, recording when the first and the final
// updates were shown.
Status waitForUpdates(Rebaker& live, Renderer& r, const Camera& camera, uint32_t terms,
                      int live_divisor, Clock::time_point since, EditTimings* t) {
  while (secondsSince(since) < kTimeoutSeconds) {
    auto shown = showUpdates(live, r, camera, terms, live_divisor);
    if (!shown) return shown.status();
    for (const LiveAtlas& u : *shown) {
      const size_t tiles = u.is_delta ? u.updates.size() : u.atlas.layout.storedTiles();
      const double received = std::chrono::duration<double>(u.received - since).count();
      if (t && t->first < 0)
        t->first = secondsSince(since), t->first_tiles = tiles, t->first_received = received;
      if (u.final) {
        if (t) t->converged = secondsSince(since), t->final_tiles = tiles, t->passes = u.passes;
        if (t) t->converged_received = received;
        if (t) t->job = u.job;
        return {};
      }
    }
    if (shown->empty()) {
      const LiveState state = live.state();
      if (state.failed && !state.busy) return Status::error(StatusCode::kIo, state.message);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  return Status::error(StatusCode::kIo,
                       "no converged update within the timeout: " + live.statusLine());
}

Status writeReport(const ViewerOptions& o, const EditTimings& t) {
  const nlohmann::json report = {{"scene", o.scene},
                                 {"edit", o.edit},
                                 {"mode", modeName(o.live_mode)},
                                 {"job", t.job},
                                 {"passes", t.passes},
                                 {"first_update_seconds", t.first},
                                 {"converged_seconds", t.converged},
                                 {"first_update_tiles", t.first_tiles},
                                 {"first_received_seconds", t.first_received},
                                 {"geometry_seconds", t.geometry},
                                 {"converged_received_seconds", t.converged_received},
                                 {"converged_tiles", t.final_tiles},
                                 {"width", o.width},
                                 {"live_divisor", o.live_divisor},
                                 {"height", o.height}};
  return writeFileAtomic(o.edit_report, report.dump(2) + "\n");
}

// The daemon's live rebakes with --server; else the in-process baker, started from --atlas
// when given (it asks for the base bake itself otherwise).
Expected<std::unique_ptr<Rebaker>> startRebaker(const ViewerOptions& o, const Scene& scene) {
  if (o.server_url.empty()) {
    std::optional<LocalSeed> seed;
    if (!o.atlas_dir.empty()) seed = LocalSeed{scene, o.atlas_dir};
    auto local = std::make_unique<LocalRebake>(o.live_mode, std::move(seed));
    if (o.atlas_dir.empty()) local->requestRebake(scene);
    return std::unique_ptr<Rebaker>(std::move(local));
  }
  LiveOptions options;
  options.mode = o.live_mode;
  options.face_light_spp = o.face_light_spp;
  auto live = LiveRebake::connect(o.server_url, scene, options);
  if (!live) return live.status();
  return std::unique_ptr<Rebaker>(std::move(*live));
}

Status runEdit(const ViewerOptions& o) {
  auto edit = parseEditCommand(o.edit);
  if (!edit) return edit.status();
  ContextOptions context_options;
  context_options.device = o.device;
  auto context = VulkanContext::create(context_options);
  if (!context) return context.status();
  auto renderer = Renderer::create(**context, rendererOptions(o, o.width, o.height));
  if (!renderer) return renderer.status();
  Renderer& r = **renderer;
  Scene scene;
  auto camera_index = loadViewerContent(r, o, scene);
  if (!camera_index) return camera_index.status();
  SceneEditor editor(scene);
  RDM_TRY(applyEditCommand(*edit, editor));  // refuse a bad edit before any bake
  auto live = startRebaker(o, scene);
  if (!live) return live.status();
  const Camera& camera = scene.cameras[*camera_index];
  if (!o.server_url.empty() || o.atlas_dir.empty()) {
    RDM_TRY(waitForUpdates(**live, r, camera, o.terms, o.live_divisor, Clock::now(), nullptr));
    std::printf("base bake on screen: %s\n", (*live)->statusLine().c_str());
  }
  // As in the window: the edit goes to the daemon at once, and the edited geometry is drawn
  // (with the old RDMs) while the rebake runs.
  const auto edited_at = Clock::now();
  (*live)->requestRebake(editor.scene());
  RDM_TRY(r.setScene(editor.scene()));
  r.setResolutionDivisor(o.live_divisor);
  if (auto frame = r.renderFrame(camera, o.terms); !frame) return frame.status();
  const double geometry_seconds = secondsSince(edited_at);
  EditTimings t;
  RDM_TRY(waitForUpdates(**live, r, camera, o.terms, o.live_divisor, edited_at, &t));
  t.geometry = geometry_seconds;
  std::printf("edited geometry on screen after %.3f s\n", t.geometry);
  std::printf("first update after %.3f s (%zu face tiles)\n", t.first, t.first_tiles);
  std::printf("converged after %.3f s (%zu face tiles, %d pass(es), job %s)\n", t.converged,
              t.final_tiles, t.passes, t.job.c_str());
  auto ldr = r.readLdr();
  if (!ldr) return ldr.status();
  RDM_TRY(writeImage8Png(o.offscreen_png, *ldr));
  return writeReport(o, t);
}

}  // namespace

int runScriptedEdit(const ViewerOptions& o) {
  if (Status s = runEdit(o); !s.ok())
    return std::fprintf(stderr, "rdm-viewer: %s\n", s.message().c_str()), 1;
  return 0;
}

}  // namespace rdm::viewer
