// The Dear ImGui control panel: per-term toggles, camera mode, edit tool, block/palette
// choice and palette editing, undo/redo, scene save/load. Only draws and records requests;
// the window applies them.
#pragma once

#include <cstdint>
#include <string>

#include "camera_controller.h"
#include "editor.h"

namespace rdm::viewer {

// Width of the panel's label column, in font sizes: every label fits
// (ViewerPanel.FitsAboveTheStatusBarAtSmallWindowSizes measures them).
inline constexpr float kPanelLabelColumnEms = 10.0f;

enum class EditTool { kNone, kAddBlock, kRemoveBlock, kCarveVoxel, kPaintVoxel };

struct PanelState {
  uint32_t terms = 0;
  CameraMode camera_mode = CameraMode::kOrbit;
  EditTool tool = EditTool::kNone;
  std::string block;     // block to add
  int rot = 0;           // its orientation
  int palette = 1;       // palette index used by paint
  int brush_radius = 0;  // carve and paint: voxels within this distance (SceneEditor::brushVoxels)
  char path[512] = "scene.json";
  std::string message;  // last status line
  double frame_ms = 0.0;
  Pick hover;
  bool server_connected = false;
  int quality = -1;        // index into the core's presets chosen last; -1: the scene's own
  std::string prediction;  // the last "predict" answer, or that one is running
  bool predicting = false;
  int reference_spp = 16;      // of "path-trace this view"
  int reference_display = 1;   // the window's right half: 0 real-time, 1 reference, 2 FLIP map
  std::string reference_text;  // progress, or the last reference's spp, seconds and LDR-FLIP
};

struct PanelRequests {
  bool undo = false, redo = false, save = false, load = false, reset_camera = false;
  bool scene_changed = false;  // the panel edited the palette through the editor
  std::string quality;         // a preset chosen now (rdm::qualityPreset), else empty
  bool predict = false;        // predict the bake at the scene's settings
  bool save_view = false;      // append the current view to the scene file's cameras (F5)
  bool path_trace = false;     // render the reference of the current view (F6)
};

PanelRequests drawPanel(PanelState& state, SceneEditor& editor);

}  // namespace rdm::viewer
