#include "live_overlay.h"

#include <cmath>
#include <cstdio>

#include <imgui.h>

namespace rdm::viewer {
namespace {

constexpr uint32_t kStaleColour = 0xff2aa0ff;  // orange
constexpr uint32_t kHoverColour = 0xffffffff;

std::string etaText(const StatusBarState& s) {
  if (!s.eta_seconds) return "";
  char text[32];
  std::snprintf(text, sizeof(text), ", about %.1f s left", *s.eta_seconds);
  return text;
}

}  // namespace

std::string progressText(const StatusBarState& s) {
  char text[128];
  std::snprintf(text, sizeof(text), "%s pass %d/%d%s  %.0f %%%s", s.mode.c_str(), s.pass + 1,
                s.passes, s.phase == "face_light" ? " face light" : "", 100.0 * s.fraction,
                etaText(s).c_str());
  return text;
}

const char* idleStatusText(const StatusBarState& s) {
  if (!s.has_atlas) return "not baked";
  return s.stale_blocks ? "edits waiting for a bake" : "RDMs up to date";
}

StatusBarRequests drawStatusBar(const StatusBarState& s) {
  StatusBarRequests r;
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  const float height = ImGui::GetFrameHeightWithSpacing() * 2.0f + 8.0f;
  ImGui::SetNextWindowPos(ImVec2(vp->WorkPos.x, vp->WorkPos.y + vp->WorkSize.y - height));
  ImGui::SetNextWindowSize(ImVec2(vp->WorkSize.x, height));
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoFocusOnAppearing;
  ImGui::Begin("##status", nullptr, flags);
  if (!s.live) {
    r.bake = ImGui::Button("bake in-process");
    ImGui::SameLine();
    ImGui::TextUnformatted("no bake daemon (--server URL); edits then rebake incrementally here");
    if (!s.message.empty()) ImGui::TextUnformatted(s.message.c_str());
    ImGui::End();
    return r;
  }
  if (!s.daemon) ImGui::TextUnformatted("in-process  ");
  if (!s.daemon) ImGui::SameLine();
  if (!s.connected) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "daemon unreachable  ");
  if (!s.connected) ImGui::SameLine();
  if (s.busy) {
    ImGui::ProgressBar(float(s.fraction), ImVec2(-120.0f, 0.0f), progressText(s).c_str());
    ImGui::SameLine();
    r.cancel = ImGui::Button("cancel bake");
  } else {
    ImGui::TextUnformatted(idleStatusText(s));
    if (!s.has_atlas) {
      ImGui::SameLine();
      r.bake = ImGui::Button("bake");
    }
  }
  if (s.stale_blocks)
    ImGui::TextColored(ImVec4(1, 0.63f, 0.16f, 1), "%d stale block(s) outlined   ", s.stale_blocks);
  if (s.stale_blocks) ImGui::SameLine();
  if (s.busy && s.preview_rdms) ImGui::Text("%d RDM(s) at preview quality   ", s.preview_rdms);
  if (s.busy && s.preview_rdms) ImGui::SameLine();
  ImGui::TextUnformatted(s.message.c_str());
  ImGui::End();
  return r;
}

void drawOutlines(const std::vector<OutlineBox>& boxes, const glm::mat4& view_projection,
                  float width, float height) {
  ImDrawList* list = ImGui::GetBackgroundDrawList();
  static const int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                    {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  for (const OutlineBox& b : boxes) {
    glm::vec4 clip[8];
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 p((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y,
                        (c & 4) ? b.hi.z : b.lo.z);
      clip[c] = view_projection * glm::vec4(p, 1.0f);
    }
    for (const auto& e : kEdges) {
      const glm::vec4 a = clip[e[0]], z = clip[e[1]];
      if (a.w <= 1e-3f || z.w <= 1e-3f) continue;  // behind the camera: skip the edge
      const ImVec2 pa((a.x / a.w * 0.5f + 0.5f) * width, (a.y / a.w * 0.5f + 0.5f) * height);
      const ImVec2 pz((z.x / z.w * 0.5f + 0.5f) * width, (z.y / z.w * 0.5f + 0.5f) * height);
      list->AddLine(pa, pz, b.rgba, 2.0f);
    }
  }
}

OutlineBox staleBox(const glm::ivec3& slot) {
  return {glm::vec3(slot) + 0.02f, glm::vec3(slot) + 0.98f, kStaleColour};
}

OutlineBox hoverBox(const Pick& pick, bool voxel, int brush_radius) {
  if (voxel) {
    const glm::vec3 lo = glm::vec3(pick.voxel - brush_radius) / 16.0f;
    return {lo, lo + float(2 * brush_radius + 1) / 16.0f, kHoverColour};
  }
  return {glm::vec3(pick.slot), glm::vec3(pick.slot) + 1.0f, kHoverColour};
}

}  // namespace rdm::viewer
