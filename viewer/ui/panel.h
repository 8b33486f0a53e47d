// The Dear ImGui control panel: per-term toggles, camera mode, edit tool, block/palette
// choice and palette editing, undo/redo, scene save/load. Only draws and records requests;
// the window applies them.
#pragma once

#include <cstdint>
#include <string>

#include "camera_controller.h"
#include "editor.h"

namespace rdm::viewer {

enum class EditTool { kNone, kAddBlock, kRemoveBlock, kCarveVoxel, kPaintVoxel };

struct PanelState {
  uint32_t terms = 0;
  CameraMode camera_mode = CameraMode::kOrbit;
  EditTool tool = EditTool::kNone;
  std::string block;  // block to add
  int rot = 0;        // its orientation
  int palette = 1;    // palette index used by paint
  char path[512] = "scene.json";
  std::string message;  // last status line
  double frame_ms = 0.0;
  Pick hover;
  bool server_connected = false;
};

struct PanelRequests {
  bool undo = false, redo = false, save = false, load = false, reset_camera = false;
  bool scene_changed = false;  // the panel edited the palette through the editor
};

PanelRequests drawPanel(PanelState& state, SceneEditor& editor);

}  // namespace rdm::viewer
