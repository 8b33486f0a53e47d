// The viewer's Dear ImGui panel and status bar, laid out by a headless ImGui context (no
// window, no renderer) at the window sizes where the first-hour issue found them clipped:
// the panel fits above the status bar and scrolls instead of being cut, the status bar
// stays on the display, and no label is wider than its column. Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <imgui.h>
#include <imgui_internal.h>

#include "editor.h"
#include "live_overlay.h"
#include "panel.h"
#include "rdm/scene/scene.h"

namespace rdm::viewer {
namespace {

struct Layout {
  ImRect panel, status;
  float label_column = 0.0f, widest_label = 0.0f;
};

// Three frames (ImGui settles window sizes over the first ones) at `w` x `h`, with the
// "under cursor" line and a status message shown.
Layout layOut(float w, float h) {
  ImGuiContext* context = ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  io.DisplaySize = ImVec2(w, h);
  io.DeltaTime = 1.0f / 60.0f;
  unsigned char* pixels = nullptr;
  int tw = 0, th = 0;
  io.Fonts->GetTexDataAsRGBA32(&pixels, &tw, &th);  // builds the font atlas
  SceneEditor editor(builtinScene("chess").value());
  PanelState panel;
  panel.hover.hit = true;
  panel.tool = EditTool::kPaintVoxel;
  panel.message = "live: scene version 3 up to date";
  StatusBarState bar;
  bar.live = bar.daemon = bar.busy = true;
  bar.mode = "exact", bar.passes = 2, bar.fraction = 0.4, bar.stale_blocks = 1;
  Layout out;
  for (int frame = 0; frame < 3; ++frame) {
    ImGui::NewFrame();
    drawPanel(panel, editor);
    drawStatusBar(bar);
    ImGui::Render();
  }
  out.panel = ImGui::FindWindowByName("rdm-viewer")->Rect();
  out.status = ImGui::FindWindowByName("##status")->Rect();
  out.label_column =
      ImGui::GetFontSize() * kPanelLabelColumnEms - ImGui::GetStyle().ItemInnerSpacing.x;
  for (const char* label : {"tool (left click)", "palette index", "colour (sRGB)", "brush radius",
                            "roughness", "metallic", "emission", "rotation", "quality"})
    out.widest_label = std::max(out.widest_label, ImGui::CalcTextSize(label).x);
  ImGui::DestroyContext(context);
  return out;
}

TEST(ViewerPanel, FitsAboveTheStatusBarAtSmallWindowSizes) {
  for (ImVec2 size : {ImVec2(640, 360), ImVec2(320, 240), ImVec2(1280, 720)}) {
    const Layout l = layOut(size.x, size.y);
    SCOPED_TRACE(std::to_string(int(size.x)) + "x" + std::to_string(int(size.y)));
    EXPECT_GE(l.panel.Min.x, 0.0f);
    EXPECT_GE(l.panel.Min.y, 0.0f);
    EXPECT_LE(l.panel.Max.x, size.x);
    EXPECT_LE(l.panel.Max.y, l.status.Min.y);  // the status line is never covered
    EXPECT_EQ(l.status.Max.y, size.y);         // anchored to the bottom edge
    EXPECT_EQ(l.status.GetWidth(), size.x);
    EXPECT_LE(l.widest_label, l.label_column);  // labels are never cut
  }
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
