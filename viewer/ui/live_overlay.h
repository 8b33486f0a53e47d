// Always-visible overlays of the window (docs/viewer.md, "Live rebakes"): a status bar with
// the live bake's pass, phase, progress, ETA, connection and a cancel button, and outlines drawn
// over the 3D view around edited blocks whose final pass has not landed and around the block or
// voxel under the cursor. Only draws; the window acts on the result.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "editor.h"

namespace rdm::viewer {

struct StatusBarState {
  bool live = false;    // a rebaker is attached
  bool daemon = false;  // it is the daemon (else the in-process bake)
  bool connected = true, busy = false;
  std::string job, mode, message;
  int pass = 0, passes = 1;
  double fraction = 0.0;
  std::optional<double> eta_seconds;
  int stale_blocks = 0;
  int preview_rdms = 0;   // RDMs at preview quality until the final pass
  std::string phase;      // "face_light" is named in the bar
  bool has_atlas = true;  // the renderer holds an atlas (false until a first bake lands)
};

struct StatusBarRequests {
  bool cancel = false;
  bool bake = false;  // bake the scene: in-process when no rebaker is attached, else with it
};

// The progress bar's text while a bake runs: "exact pass 2/2 face light  93 %, about 1.2 s
// left" (the phase is named only for the face light; the ETA once there is one).
std::string progressText(const StatusBarState& state);

// What the status bar says about the RDMs when no bake is running: "not baked" without an
// atlas (e.g. the first bake was cancelled), "edits waiting for a bake" with stale blocks,
// else "RDMs up to date".
const char* idleStatusText(const StatusBarState& state);

// Anchored to the bottom edge of the display; never scrolled or clipped by the panel.
StatusBarRequests drawStatusBar(const StatusBarState& state);

// World-space boxes (in block units) outlined through `view_projection` (Vulkan clip space)
// onto a framebuffer of `width` x `height` pixels.
struct OutlineBox {
  glm::vec3 lo{0.0f}, hi{1.0f};
  uint32_t rgba = 0xff00ffff;  // ImGui's ABGR byte order
};
void drawOutlines(const std::vector<OutlineBox>& boxes, const glm::mat4& view_projection,
                  float width, float height);

// A stale block's outline, and the hovered block's (or, for voxel tools, the box around the
// voxels a brush of `brush_radius` reaches).
OutlineBox staleBox(const glm::ivec3& slot);
OutlineBox hoverBox(const Pick& pick, bool voxel, int brush_radius = 0);

}  // namespace rdm::viewer
