#include "panel.h"

#include <algorithm>

#include <imgui.h>

#include "gpu_layout.h"

namespace rdm::viewer {
namespace {

void termToggles(uint32_t& terms) {
  const std::pair<const char*, uint32_t> kTerms[] = {
      {"RDM lookups (unticked: flat ambient)", kTermRdm},
      {"indirect diffuse", kTermDiffuse},
      {"indirect specular", kTermSpecular},
      {"sun", kTermSun},
      {"sun shadows", kTermShadows},
      {"emission", kTermEmission},
      {"sky background", kTermBackground},
      {"in-block reflections", kTermInBlock},
      {"face light", kTermFaceLight},
      {"blend RDMs across blocks", kTermBlockBlend},
      {"filter the face light", kTermFaceLightFilter}};
  for (const auto& [label, bit] : kTerms) {
    bool on = (terms & bit) != 0;
    if (ImGui::Checkbox(label, &on)) terms = on ? (terms | bit) : (terms & ~bit);
  }
}

void toolChoice(PanelState& s, const Scene& scene) {
  const char* kTools[] = {"inspect", "add block", "remove block", "carve voxel", "paint voxel"};
  int tool = int(s.tool);
  if (ImGui::Combo("tool (left click)", &tool, kTools, 5)) s.tool = EditTool(tool);
  if (ImGui::BeginCombo("block", s.block.c_str())) {
    for (const auto& [name, block] : scene.blocks) {
      if (ImGui::Selectable(name.c_str(), name == s.block)) s.block = name;
    }
    ImGui::EndCombo();
  }
  ImGui::SliderInt("rotation", &s.rot, 0, 23);
  if (s.tool == EditTool::kCarveVoxel || s.tool == EditTool::kPaintVoxel) {
    ImGui::SliderInt("brush radius", &s.brush_radius, 0, 8);
    ImGui::TextDisabled("drag to carve or paint; one undo per stroke");
  }
}

// Palette list with the selected entry's editors; returns true when the entry changed.
bool paletteEditor(PanelState& s, SceneEditor& editor) {
  const Scene& scene = editor.scene();
  if (scene.palette.empty()) return false;
  s.palette = std::clamp(s.palette, 1, int(scene.palette.size()));
  ImGui::SliderInt("palette index", &s.palette, 1, int(scene.palette.size()));
  PaletteEntry e = scene.palette[s.palette - 1];
  float color[3] = {e.color[0] / 255.0f, e.color[1] / 255.0f, e.color[2] / 255.0f};
  bool changed = ImGui::ColorEdit3("colour (sRGB)", color);
  changed |= ImGui::SliderInt("roughness", &e.roughness, 0, 7);
  changed |= ImGui::SliderInt("metallic", &e.metallic, 0, 3);
  changed |= ImGui::SliderInt("emission", &e.emission, 0, 3);
  if (ImGui::Button("new palette entry")) {
    s.palette = editor.addPaletteEntry(e);
    return true;
  }
  if (!changed) return false;
  for (int c = 0; c < 3; ++c) e.color[c] = std::clamp(int(color[c] * 255.0f + 0.5f), 0, 255);
  return editor.setPaletteEntry(s.palette, e);
}

// Quality presets (docs/spec.md section 3.1) and the predicted cost of the scene's bake.
void qualityChoice(PanelState& s, const BakeSettings& bake, PanelRequests& r) {
  const char* kPresets[] = {"draft", "preview", "final"};
  const char* shown = s.quality >= 0 ? kPresets[s.quality] : "scene's own";
  if (ImGui::BeginCombo("quality", shown)) {
    for (int i = 0; i < 3; ++i) {
      if (ImGui::Selectable(kPresets[i], i == s.quality)) s.quality = i, r.quality = kPresets[i];
    }
    ImGui::EndCombo();
  }
  ImGui::Text("%d spp, %d bounces, S <= %d, %s", bake.spp, bake.max_bounces, bake.max_hemisphere,
              estimatorName(bake.estimator));
  ImGui::BeginDisabled(s.predicting);
  r.predict = ImGui::Button("predict time and noise");
  ImGui::EndDisabled();
  if (!s.prediction.empty()) ImGui::TextWrapped("%s", s.prediction.c_str());
}

// "path-trace this view", its samples, what the right half shows, and the last result.
void referenceControls(PanelState& s, PanelRequests& r) {
  r.path_trace = ImGui::Button("path-trace this view (F6)");
  ImGui::SliderInt("reference spp", &s.reference_spp, 1, 256, "%d", ImGuiSliderFlags_Logarithmic);
  ImGui::RadioButton("real-time", &s.reference_display, 0);
  ImGui::SameLine();
  ImGui::RadioButton("reference", &s.reference_display, 1);
  ImGui::SameLine();
  ImGui::RadioButton("FLIP map", &s.reference_display, 2);
  if (!s.reference_text.empty()) ImGui::TextWrapped("%s", s.reference_text.c_str());
}

}  // namespace

PanelRequests drawPanel(PanelState& s, SceneEditor& editor) {
  PanelRequests r;
  // Resizable, and never taller than the display above the status bar: past that it
  // scrolls, so nothing is clipped at small window sizes.
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  const float status_bar = ImGui::GetFrameHeightWithSpacing() * 2.0f + 16.0f;
  const float max_h = std::max(120.0f, vp->WorkSize.y - status_bar);
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(std::min(420.0f, vp->WorkSize.x - 16.0f), max_h * 0.9f),
                           ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSizeConstraints(ImVec2(220.0f, 120.0f), ImVec2(vp->WorkSize.x, max_h));
  ImGui::Begin("rdm-viewer");
  // Widgets take what is left after a label column, so labels are never cut.
  ImGui::PushItemWidth(-ImGui::GetFontSize() * kPanelLabelColumnEms);
  ImGui::Text("frame %.2f ms%s", s.frame_ms, s.server_connected ? "  (live rebakes)" : "");
  if (ImGui::CollapsingHeader("shading terms", ImGuiTreeNodeFlags_DefaultOpen))
    termToggles(s.terms);
  if (ImGui::CollapsingHeader("camera", ImGuiTreeNodeFlags_DefaultOpen)) {
    int mode = int(s.camera_mode);
    ImGui::RadioButton("orbit", &mode, 0);
    ImGui::SameLine();
    ImGui::RadioButton("fly (WASD QE)", &mode, 1);
    s.camera_mode = CameraMode(mode);
    r.reset_camera = ImGui::Button("reset to scene camera");
    r.save_view = ImGui::Button("save view as scene camera (F5)");
    referenceControls(s, r);
    ImGui::TextDisabled("right drag: rotate, middle drag: pan, wheel: zoom/speed");
  }
  if (ImGui::CollapsingHeader("edit", ImGuiTreeNodeFlags_DefaultOpen)) {
    toolChoice(s, editor.scene());
    r.scene_changed = paletteEditor(s, editor);
    ImGui::BeginDisabled(!editor.canUndo());
    r.undo = ImGui::Button("undo (Ctrl+Z)");
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(!editor.canRedo());
    r.redo = ImGui::Button("redo (Ctrl+Y)");
    ImGui::EndDisabled();
    if (s.hover.hit) {
      ImGui::Text("under cursor: slot (%d %d %d) voxel (%d %d %d)", s.hover.slot.x, s.hover.slot.y,
                  s.hover.slot.z, s.hover.voxel.x & 15, s.hover.voxel.y & 15, s.hover.voxel.z & 15);
    }
  }
  if (ImGui::CollapsingHeader("bake quality")) qualityChoice(s, editor.scene().bake, r);
  if (ImGui::CollapsingHeader("scene file")) {
    ImGui::InputText("path", s.path, sizeof(s.path));
    r.save = ImGui::Button("save");
    ImGui::SameLine();
    r.load = ImGui::Button("load");
  }
  if (!s.message.empty()) ImGui::TextWrapped("%s", s.message.c_str());
  ImGui::PopItemWidth();
  ImGui::End();
  return r;
}

}  // namespace rdm::viewer
