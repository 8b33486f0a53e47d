// Input handling of the window: cameras, hover picking, edit tools, shortcuts, panel requests.
#include <algorithm>
#include <cstdio>
#include <future>

#include <imgui.h>

#include "rdm/bake/bake.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/bake/render.h"
#include "rdm/base/parallel.h"
#include "rdm/base/thread_priority.h"
#include "rdm/scene/world.h"
#include "vk_check.h"
#include "window_app.h"

namespace rdm::viewer {

void WindowApp::updateCamera(float dt) {
  glm::dvec2 cursor;
  glfwGetCursorPos(window_, &cursor.x, &cursor.y);
  const glm::vec2 delta = glm::vec2(cursor - last_cursor_);
  last_cursor_ = cursor;
  const ImGuiIO& io = ImGui::GetIO();
  CameraInput in;
  in.dt = dt;
  if (!io.WantCaptureMouse) {
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS) in.rotate = delta;
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) in.pan = delta;
    in.scroll = input_.scroll;
  }
  input_.scroll = 0.0f;
  if (!io.WantCaptureKeyboard) {
    auto key = [&](int k) { return glfwGetKey(window_, k) == GLFW_PRESS ? 1.0f : 0.0f; };
    in.move = {key(GLFW_KEY_D) - key(GLFW_KEY_A), key(GLFW_KEY_E) - key(GLFW_KEY_Q),
               key(GLFW_KEY_W) - key(GLFW_KEY_S)};
  }
  camera_.update(in);
}

void WindowApp::updateHover() {
  panel_.hover = Pick();
  if (ImGui::GetIO().WantCaptureMouse) return;
  int win_w = 0, win_h = 0;
  glfwGetWindowSize(window_, &win_w, &win_h);
  if (win_w <= 0 || win_h <= 0) return;
  const float px = float(last_cursor_.x) * float(renderer_->width()) / float(win_w);
  const float py = float(last_cursor_.y) * float(renderer_->height()) / float(win_h);
  const Camera camera = camera_.camera();
  const glm::vec3 dir = cameraRayDirection(camera, renderer_->width(), renderer_->height(), px, py);
  panel_.hover = pickVoxel(renderer_->world(), glm::vec3(camera.position), dir);
}

void WindowApp::pollShortcuts() {
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  const bool ctrl = glfwGetKey(window_, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
                    glfwGetKey(window_, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
  const bool undo = ctrl && glfwGetKey(window_, GLFW_KEY_Z) == GLFW_PRESS;
  const bool redo = ctrl && glfwGetKey(window_, GLFW_KEY_Y) == GLFW_PRESS;
  PanelRequests r;
  r.undo = undo && !undo_key_was_down_;
  r.redo = redo && !redo_key_was_down_;
  undo_key_was_down_ = undo, redo_key_was_down_ = redo;
  if (r.undo || r.redo) {
    if (Status s = handleRequests(r); !s.ok()) panel_.message = s.message();
  }
}

// Carve and paint are strokes: the brush applies at every voxel the cursor crosses while the
// button is held (one undo step per stroke), the meshes follow at once, and the rebake goes
// out when the button is released.
Status WindowApp::applyStroke(bool down) {
  const bool pressed = down && !left_was_down_;
  if (pressed && (ImGui::GetIO().WantCaptureMouse || !panel_.hover.hit)) return Status();
  if (pressed) stroke_ = Stroke{true, false, panel_.hover.voxel - glm::ivec3(1 << 20)};
  if (!stroke_.active) return Status();
  if (!down) {  // released
    const bool changed = stroke_.changed;
    stroke_ = Stroke{};
    return changed ? syncScene() : Status();
  }
  if (!panel_.hover.hit || panel_.hover.voxel == stroke_.last) return Status();
  stroke_.last = panel_.hover.voxel;
  const uint8_t palette = panel_.tool == EditTool::kPaintVoxel ? uint8_t(panel_.palette) : 0;
  if (!editor_->brushVoxels(panel_.hover.voxel, panel_.brush_radius, palette, stroke_.changed))
    return Status();
  stroke_.changed = true;
  panel_.message = "edited; RDMs of changed slots are stale until rebaked";
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  return renderer_->setScene(editor_->scene());
}

Status WindowApp::applyTool() {
  const bool down = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  const bool clicked = left_was_down_ && !down && glm::length(last_cursor_ - press_cursor_) < 4.0;
  if (down && !left_was_down_) press_cursor_ = last_cursor_;
  if (panel_.tool == EditTool::kCarveVoxel || panel_.tool == EditTool::kPaintVoxel) {
    Status s = applyStroke(down);
    left_was_down_ = down;
    return s;
  }
  left_was_down_ = down;
  if (!clicked || ImGui::GetIO().WantCaptureMouse || !panel_.hover.hit) return Status();
  const Pick& p = panel_.hover;
  bool changed = false;
  switch (panel_.tool) {
    case EditTool::kNone:
      return Status();
    case EditTool::kAddBlock: {
      glm::ivec3 target = (p.voxel + p.normal) >> 4;
      if (target == p.slot) target = p.slot + p.normal;  // clicked a carved interior face
      changed = editor_->addBlock(target, panel_.block, panel_.rot);
      break;
    }
    case EditTool::kRemoveBlock:
      changed = editor_->removeBlock(p.slot);
      break;
    case EditTool::kCarveVoxel:
    case EditTool::kPaintVoxel:
      return Status();  // strokes (applyStroke)
  }
  panel_.message = changed ? "edited; RDMs of changed slots are stale until rebaked"
                           : "edit does not apply here";
  return changed ? syncScene() : Status();
}

Status WindowApp::syncScene() {
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  if (live_) live_->requestRebake(editor_->scene());  // first, so the rebake starts at once
  RDM_TRY(renderer_->setScene(editor_->scene()));
  return Status();
}

Status WindowApp::handleRequests(const PanelRequests& r) {
  bool changed = r.scene_changed;
  if (r.undo) changed |= editor_->undo();
  if (r.redo) changed |= editor_->redo();
  if (r.reset_camera) camera_.reset(scene_camera_);
  if (!r.quality.empty()) {
    auto preset = qualityPreset(r.quality);
    if (!preset) return preset.status();
    const bool now = editor_->setBakeSettings(withPreset(editor_->scene().bake, *preset));
    changed |= now;
    panel_.message = "quality " + r.quality + (now ? ": every RDM is rebaked" : ": unchanged");
    panel_.prediction.clear();
  }
  if (r.predict) startPrediction();
  if (r.save) {
    const Status s = saveSceneFile(panel_.path, editor_->scene());
    panel_.message = s.ok() ? std::string("saved ") + panel_.path : s.message();
  }
  if (r.load) {
    auto scene = loadSceneFile(panel_.path);
    if (scene) {
      editor_->replaceScene(std::move(*scene));
      changed = true;
      panel_.message = std::string("loaded ") + panel_.path;
    } else {
      panel_.message = scene.error();
    }
  }
  return changed ? syncScene() : Status();
}

// The pilot bake runs on its own thread at background priority; the answer is a line of text.
void WindowApp::startPrediction() {
  if (prediction_.valid()) return;
  const Scene scene = editor_->scene();
  panel_.predicting = true, panel_.prediction = "predicting...";
  prediction_ = std::async(std::launch::async, [scene]() -> std::string {
    lowerThreadPriority();
    try {
      const VoxelWorld world = buildWorld(scene);
      const int threads = workerCount(0);
      const BakePrediction p = predictBake(world, scene.bake, listRdms(world, scene.bake), threads);
      char line[200];
      std::snprintf(line, sizeof(line),
                    "predicted: %s, mean relative standard error %.2f %% (pilot of %d of %d "
                    "slots took %.2f s)",
                    predictedTimeText(p.seconds).c_str(), 100.0 * p.relative_error, p.pilot_slots,
                    p.slots, p.pilot_seconds);
      return line;
    } catch (const std::exception& e) {
      return std::string("prediction failed: ") + e.what();
    }
  });
}

void WindowApp::pollPrediction() {
  if (!prediction_.valid() ||
      prediction_.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
    return;
  panel_.prediction = prediction_.get();
  panel_.predicting = false;
  redraw_ = true;
}

}  // namespace rdm::viewer
