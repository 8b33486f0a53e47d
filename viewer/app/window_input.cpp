// Input handling of the window: cameras, hover picking, edit tools, shortcuts, panel requests.
// Presses, releases and shortcuts come from the queue (input_queue.h), in order; the camera's
// held keys and drags and the hover are polled once per frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <utility>

#include <imgui.h>
#include <imgui_internal.h>

#include "rdm/bake/bake.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/bake/render.h"
#include "rdm/base/parallel.h"
#include "rdm/base/thread_priority.h"
#include "rdm/scene/world.h"
#include "vk_check.h"
#include "window_app.h"

namespace rdm::viewer {
namespace {

// Whether Dear ImGui takes a left press at `cursor` (window coordinates): over one of the
// windows it drew this frame, or anywhere while a popup is open (the press closes it). Asked
// per queued event, since the cursor may have moved on before the frame.
bool imguiTakesPressAt(glm::dvec2 cursor) {
  const ImGuiContext& g = *ImGui::GetCurrentContext();
  if (!g.OpenPopupStack.empty()) return true;
  const ImVec2 p(float(cursor.x), float(cursor.y));
  for (const ImGuiWindow* w : g.Windows) {
    const bool takes_mouse = !(w->Flags & ImGuiWindowFlags_NoMouseInputs);
    if (w->Active && !w->Hidden && takes_mouse && w->Rect().Contains(p)) return true;
  }
  return false;
}

// One line on stdout per edit the window applies, flushed (tests follow the window by it).
void printEdit(const char* what) {
  std::printf("edit: %s\n", what);
  std::fflush(stdout);
}

// "view_<n>" for the first n that no camera of `scene` is named.
std::string freeViewName(const Scene& scene) {
  for (int n = 0;; ++n) {
    const std::string name = "view_" + std::to_string(n);
    if (std::none_of(scene.cameras.begin(), scene.cameras.end(),
                     [&](const Camera& c) { return c.name == name; }))
      return name;
  }
}

// The scene file with `camera` appended under the first free "view_<n>"; that name.
Expected<std::string> appendCameraToFile(const std::string& path, Camera camera) {
  auto scene = loadSceneFile(path);
  if (!scene) return scene.status();
  camera.name = freeViewName(*scene);
  scene->cameras.push_back(camera);
  RDM_TRY(saveSceneFile(path, *scene));
  return camera.name;
}

// `view` at 1e-6 units (beyond a float's precision at scene scale; short in the JSON) under
// the first free "view_<n>" of `scene`'s file; that name. Refuses a built-in scene and a view
// without a camera basis.
Expected<std::string> saveView(const std::string& scene, Camera view) {
  const std::vector<std::string> builtins = builtinSceneNames();
  if (std::find(builtins.begin(), builtins.end(), scene) != builtins.end()) {
    return Status::error("scene '" + scene + "' is built in; export it with `rdm scene --scene " +
                         scene + " -o " + scene + ".json` and start the viewer with --scene " +
                         scene + ".json");
  }
  view.position = glm::round(view.position * 1e6) / 1e6;
  view.target = glm::round(view.target * 1e6) / 1e6;
  view.fov_deg = std::round(view.fov_deg * 1e6) / 1e6;
  if (!cameraUsable(view))
    return Status::error("the view looks straight up or down (no camera basis)");
  return appendCameraToFile(scene, view);
}

}  // namespace

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
    in.scroll = input_.takeScroll();
  }
  input_.takeScroll();  // wheel turns over ImGui are its own
  if (!io.WantCaptureKeyboard) {
    auto key = [&](int k) { return glfwGetKey(window_, k) == GLFW_PRESS ? 1.0f : 0.0f; };
    in.move = {key(GLFW_KEY_D) - key(GLFW_KEY_A), key(GLFW_KEY_E) - key(GLFW_KEY_Q),
               key(GLFW_KEY_W) - key(GLFW_KEY_S)};
  }
  camera_.update(in);
}

Pick WindowApp::pickAt(glm::dvec2 cursor) const {
  int win_w = 0, win_h = 0;
  glfwGetWindowSize(window_, &win_w, &win_h);
  if (win_w <= 0 || win_h <= 0) return Pick();
  const float px = float(cursor.x) * float(renderer_->width()) / float(win_w);
  const float py = float(cursor.y) * float(renderer_->height()) / float(win_h);
  const Camera camera = camera_.camera();
  const glm::vec3 dir = cameraRayDirection(camera, renderer_->width(), renderer_->height(), px, py);
  return pickVoxel(renderer_->world(), glm::vec3(camera.position), dir);
}

void WindowApp::updateHover() {
  panel_.hover = ImGui::GetIO().WantCaptureMouse ? Pick() : pickAt(last_cursor_);
}

Status WindowApp::consumeInput() {
  for (const InputEvent& e : input_.takeEvents()) {
    if (e.kind == InputEvent::Kind::kKey) RDM_TRY(onShortcut(e));
    if (e.kind == InputEvent::Kind::kButton && e.code == GLFW_MOUSE_BUTTON_LEFT)
      RDM_TRY(onLeftButton(e));
  }
  // The drag of a stroke follows the cursor polled this frame.
  if (stroke_.active && left_.down) return strokeAt(panel_.hover);
  return Status();
}

Status WindowApp::onShortcut(const InputEvent& e) {
  if (e.action != GLFW_PRESS) return Status();
  if (ImGui::GetIO().WantCaptureKeyboard) return Status();  // e.g. typing a scene path
  const bool ctrl = (e.mods & GLFW_MOD_CONTROL) != 0;
  PanelRequests r;
  r.undo = ctrl && e.code == GLFW_KEY_Z;
  r.redo = ctrl && e.code == GLFW_KEY_Y;
  r.save_view = !ctrl && e.code == GLFW_KEY_F5;
  r.path_trace = !ctrl && e.code == GLFW_KEY_F6;
  if (!r.undo && !r.redo && !r.save_view && !r.path_trace) return Status();
  if (Status s = handleRequests(r); !s.ok()) panel_.message = s.message();
  return Status();
}

// Block tools act on a click (press and release within 4 px, the press over the 3D view).
// Carve and paint are strokes: the brush applies at every voxel the cursor crosses while the
// button is held (one undo step per stroke), the meshes follow at once, and the rebake goes
// out when the button is released.
Status WindowApp::onLeftButton(const InputEvent& e) {
  const bool voxel_tool =
      panel_.tool == EditTool::kCarveVoxel || panel_.tool == EditTool::kPaintVoxel;
  if (e.action == GLFW_PRESS) {
    left_ = LeftPress{true, !imguiTakesPressAt(e.cursor), e.cursor};
    if (!left_.world || !voxel_tool) return Status();
    const Pick p = pickAt(e.cursor);
    if (!p.hit) return Status();
    stroke_ = Stroke{true, false, p.voxel - glm::ivec3(1 << 20)};
    return strokeAt(p);
  }
  if (e.action != GLFW_RELEASE || !left_.down) return Status();
  const LeftPress press = std::exchange(left_, LeftPress{});
  if (stroke_.active) {
    RDM_TRY(strokeAt(pickAt(e.cursor)));
    return endStroke();
  }
  if (!press.world || voxel_tool || glm::length(e.cursor - press.at) >= 4.0) return Status();
  const Pick p = pickAt(press.at);
  return p.hit ? applyClick(p) : Status();
}

Status WindowApp::applyClick(const Pick& p) {
  bool changed = false;
  char line[96] = "";
  switch (panel_.tool) {
    case EditTool::kNone:
    case EditTool::kCarveVoxel:
    case EditTool::kPaintVoxel:  // strokes (strokeAt)
      return Status();
    case EditTool::kAddBlock: {
      glm::ivec3 target = (p.voxel + p.normal) >> 4;
      if (target == p.slot) target = p.slot + p.normal;  // clicked a carved interior face
      changed = editor_->addBlock(target, panel_.block, panel_.rot);
      std::snprintf(line, sizeof(line), "add block %d,%d,%d", target.x, target.y, target.z);
      break;
    }
    case EditTool::kRemoveBlock:
      changed = editor_->removeBlock(p.slot);
      std::snprintf(line, sizeof(line), "remove block %d,%d,%d", p.slot.x, p.slot.y, p.slot.z);
      break;
  }
  panel_.message = changed ? "edited; RDMs of changed slots are stale until rebaked"
                           : "edit does not apply here";
  if (!changed) return Status();
  printEdit(line);
  return syncScene();
}

Status WindowApp::strokeAt(const Pick& p) {
  if (!stroke_.active || !p.hit || p.voxel == stroke_.last) return Status();
  stroke_.last = p.voxel;
  const uint8_t palette = panel_.tool == EditTool::kPaintVoxel ? uint8_t(panel_.palette) : 0;
  if (!editor_->brushVoxels(p.voxel, panel_.brush_radius, palette, stroke_.changed))
    return Status();
  stroke_.changed = true;
  panel_.message = "edited; RDMs of changed slots are stale until rebaked";
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  return renderer_->setScene(editor_->scene());
}

Status WindowApp::endStroke() {
  const bool changed = stroke_.changed;
  stroke_ = Stroke{};
  if (!changed) return Status();
  printEdit(panel_.tool == EditTool::kPaintVoxel ? "paint stroke" : "carve stroke");
  return syncScene();
}

Status WindowApp::syncScene() {
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  if (live_) live_->requestRebake(editor_->scene());  // first, so the rebake starts at once
  RDM_TRY(renderer_->setScene(editor_->scene()));
  return Status();
}

Status WindowApp::handleRequests(const PanelRequests& r) {
  bool changed = r.scene_changed;
  if (r.undo && editor_->undo()) changed = true, printEdit("undo");
  if (r.redo && editor_->redo()) changed = true, printEdit("redo");
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
  if (r.save_view) saveViewAsCamera();
  if (r.path_trace) startReference();
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

void WindowApp::saveViewAsCamera() {
  auto saved = saveView(options_.scene, camera_.camera());
  if (saved) {  // the panel's "save" writes the editor's scene: it keeps the camera too
    Camera kept = camera_.camera();
    kept.name = *saved;
    editor_->putCamera(kept);
  }
  panel_.message = saved ? "camera: saved " + *saved + " to " + options_.scene
                         : "camera: not saved: " + saved.error();
  std::printf("%s\n", panel_.message.c_str());
  std::fflush(stdout);
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
