// The interactive window: GLFW + swapchain, the renderer's image blitted in, an ImGui panel
// on top, orbit/fly cameras, picking and editing, optional live rebakes.
#pragma once

#include <chrono>
#include <future>
#include <memory>
#include <optional>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "input_queue.h"
#include "live_overlay.h"
#include "live_rebake.h"
#include "local_rebake.h"
#include "options.h"
#include "panel.h"
#include "reference_view.h"
#include "renderer.h"
#include "swapchain.h"

namespace rdm::viewer {

class WindowApp {
 public:
  explicit WindowApp(const ViewerOptions& options) : options_(options) {}
  ~WindowApp();
  Status init();
  Status run();  // until the window closes or --frames frames were shown

 private:
  Status initImgui();
  Status frame();
  Status recordAndSubmit(uint32_t image_index);
  Status handleRequests(const PanelRequests& r);
  Status consumeInput();  // the queued events, in order, then the stroke's drag
  Status onShortcut(const InputEvent& e);
  Status onLeftButton(const InputEvent& e);
  Status applyClick(const Pick& p);
  Status strokeAt(const Pick& p);
  Status endStroke();
  Status syncScene();
  // Appends the current view to --scene's file as camera "view_<n>" (the first n free there),
  // written atomically. Prints "camera: saved view_<n> to FILE", or "camera: not saved: WHY"
  // for a built-in scene, a view straight up or down, or a file it cannot read or write; the
  // same line goes to the status line.
  void saveViewAsCamera();
  void updateCamera(float dt);
  Pick pickAt(glm::dvec2 cursor) const;
  void updateHover();
  void finishFrameTime(std::chrono::steady_clock::time_point start);  // --min-frame-ms
  bool waitForWork();  // render on demand: false when nothing changed since the last frame
  void applyLiveUpdates();
  void drawOverlays();
  void startPrediction();
  // "path-trace this view" (window_reference.cpp): start, poll, and the right half's copy.
  void startReference();
  Status pollReference();
  std::string compareReference();
  Status prepareReferenceUpload();
  void recordReferenceCopy(VkCommandBuffer cmd, VkImage target) const;
  void drawReferenceDivider() const;
  bool referenceShown() const;
  void pollPrediction();

  ViewerOptions options_;
  GLFWwindow* window_ = nullptr;
  bool glfw_ready_ = false, imgui_ready_ = false;
  std::unique_ptr<VulkanContext> context_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<Swapchain> swapchain_;
  std::unique_ptr<SceneEditor> editor_;
  std::unique_ptr<Rebaker> live_;  // the daemon (--server) or, after "bake", the core in-process
  std::optional<LocalSeed> local_seed_;
  ReferenceRender reference_;
  std::optional<ReferenceImage> reference_image_;  // the last finished reference
  Image8 reference_flip_map_;                      // its FLIP map against the real-time image
  GpuBuffer reference_upload_;                     // the right half, in the swapchain's format
  int reference_uploaded_ = -1;  // reference_display that buffer holds  // --atlas and the scene as
                                 // loaded, for the first "bake"
  bool daemon_ = false;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkSemaphore acquired_ = VK_NULL_HANDLE, finished_ = VK_NULL_HANDLE;
  VkDescriptorPool imgui_pool_ = VK_NULL_HANDLE;
  CameraController camera_;
  PanelState panel_;
  Camera scene_camera_;
  int frames_shown_ = 0;
  bool resize_pending_ = false;
  // Filled by GLFW callbacks (the window's user pointer); ImGui chains to them.
  InputQueue input_;
  uint64_t input_seen_ = 0;
  std::chrono::steady_clock::time_point last_input_, last_progress_draw_;
  bool redraw_ = true;
  glm::dvec2 last_cursor_{0.0};
  struct LeftPress {
    bool down = false;   // between a queued press and its release
    bool world = false;  // the press was over the 3D view, not over an ImGui window
    glm::dvec2 at{0.0};  // where it went down
  } left_;
  struct Stroke {
    bool active = false;   // the left button went down over the scene with a voxel tool
    bool changed = false;  // the stroke has changed the scene (its undo step exists)
    glm::ivec3 last{0};    // the voxel the brush was last applied at
  } stroke_;
  std::chrono::steady_clock::time_point last_time_;
  std::future<std::string> prediction_;  // the panel's "predict", on its own thread
};

}  // namespace rdm::viewer
