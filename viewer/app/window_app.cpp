#include "window_app.h"

#include <cstdio>
#include <thread>
#include <utility>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>

#include "camera.h"
#include "rdm/bake/render.h"
#include "run_modes.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

void checkImguiVk(VkResult r) {
  if (r != VK_SUCCESS)
    std::fprintf(stderr, "rdm-viewer: ImGui Vulkan backend: %s\n", vkResultName(r));
}

InputQueue& inputOf(GLFWwindow* window) {
  return *static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
}
void onScroll(GLFWwindow* window, double, double dy) {
  inputOf(window).scrolled(float(dy));
}
void onCursor(GLFWwindow* window, double x, double y) {
  inputOf(window).cursorMoved({x, y});
}
void onButton(GLFWwindow* window, int button, int action, int mods) {
  inputOf(window).button(button, action, mods);
}
void onKey(GLFWwindow* window, int key, int, int action, int mods) {
  inputOf(window).key(key, action, mods);
}
void onChar(GLFWwindow* window, unsigned int) {
  inputOf(window).touched();
}
void onResize(GLFWwindow* window, int, int) {
  inputOf(window).touched();
}
void onRefresh(GLFWwindow* window) {
  inputOf(window).touched();
}

// --tool NAME (options.cpp checks the names).
EditTool toolNamed(const std::string& name) {
  if (name == "add") return EditTool::kAddBlock;
  if (name == "remove") return EditTool::kRemoveBlock;
  if (name == "carve") return EditTool::kCarveVoxel;
  if (name == "paint") return EditTool::kPaintVoxel;
  return EditTool::kNone;
}

// Frames keep coming this long after the last input, so ImGui settles hover and clicks.
constexpr double kSettleSeconds = 0.3;
// While a live bake runs, the status bar redraws at this interval.
constexpr double kProgressSeconds = 0.25;

}  // namespace

Status WindowApp::init() {
  if (!glfwInit()) return Status::error("cannot initialise GLFW (no display? try xvfb-run -a)");
  glfw_ready_ = true;
  if (!glfwVulkanSupported()) return Status::error("GLFW found no Vulkan loader or driver");
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(options_.width, options_.height, "rdm-viewer", nullptr, nullptr);
  if (!window_) return Status::error("cannot create a GLFW window");
  glfwSetWindowUserPointer(window_, &input_);
  glfwSetScrollCallback(window_, onScroll);
  glfwSetCursorPosCallback(window_, onCursor);
  glfwSetMouseButtonCallback(window_, onButton);
  glfwSetKeyCallback(window_, onKey);
  glfwSetCharCallback(window_, onChar);
  glfwSetFramebufferSizeCallback(window_, onResize);
  glfwSetWindowRefreshCallback(window_, onRefresh);
  glm::dvec2 cursor{0.0};
  glfwGetCursorPos(window_, &cursor.x, &cursor.y);
  input_.cursorMoved(cursor);  // a click before the first move happens where the cursor is
  ContextOptions context_options;
  uint32_t count = 0;
  const char** extensions = glfwGetRequiredInstanceExtensions(&count);
  for (uint32_t i = 0; i < count; ++i) context_options.instance_extensions.push_back(extensions[i]);
  context_options.make_surface = [this](VkInstance instance) -> Expected<VkSurfaceKHR> {
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    RDM_VK_TRY(glfwCreateWindowSurface(instance, window_, nullptr, &surface));
    return surface;
  };
  context_options.device = options_.device;
  auto context = VulkanContext::create(context_options);
  if (!context) return context.status();
  context_ = std::move(*context);
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window_, &fb_w, &fb_h);
  auto renderer =
      Renderer::create(*context_, rendererOptions(options_, std::max(fb_w, 1), std::max(fb_h, 1)));
  if (!renderer) return renderer.status();
  renderer_ = std::move(*renderer);
  renderer_->setAccumulationLimit(options_.aa_frames);
  Scene scene;
  auto camera_index = loadViewerContent(*renderer_, options_, scene);
  if (!camera_index) return camera_index.status();
  scene_camera_ = scene.cameras[*camera_index];
  camera_.reset(scene_camera_);
  editor_ = std::make_unique<SceneEditor>(scene);
  if (!options_.atlas_dir.empty()) local_seed_ = LocalSeed{scene, options_.atlas_dir};
  panel_.terms = options_.terms;
  panel_.block = scene.blocks.empty() ? "" : scene.blocks.begin()->first;
  panel_.tool = toolNamed(options_.tool);
  swapchain_ = std::make_unique<Swapchain>(*context_);
  RDM_TRY(swapchain_->create(fb_w, fb_h));
  RDM_TRY(renderer_->resize(int(swapchain_->extent().width), int(swapchain_->extent().height)));
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = context_->commandPool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  RDM_VK_TRY(vkAllocateCommandBuffers(context_->device(), &alloc, &cmd_));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  RDM_VK_TRY(vkCreateFence(context_->device(), &fence, nullptr, &fence_));
  VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  RDM_VK_TRY(vkCreateSemaphore(context_->device(), &semaphore, nullptr, &acquired_));
  RDM_VK_TRY(vkCreateSemaphore(context_->device(), &semaphore, nullptr, &finished_));
  if (!options_.server_url.empty()) {
    LiveOptions live_options;
    live_options.mode = options_.live_mode;
    live_options.face_light_spp = options_.face_light_spp;
    auto live = LiveRebake::connect(options_.server_url, scene, live_options);
    if (!live) return live.status();
    live_ = std::move(*live);
    daemon_ = true;
    panel_.server_connected = true;
  }
  RDM_TRY(initImgui());
  last_time_ = std::chrono::steady_clock::now();
  std::printf("device: %s\n%s\n", context_->deviceDescription().c_str(),
              rdmState(options_, *renderer_));
  std::fflush(stdout);  // tests wait for this line before they send input
  return Status();
}

Status WindowApp::initImgui() {
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  pool.maxSets = 16;
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &size;
  RDM_VK_TRY(vkCreateDescriptorPool(context_->device(), &pool, nullptr, &imgui_pool_));
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  if (!ImGui_ImplGlfw_InitForVulkan(window_, true))
    return Status::error("ImGui GLFW backend failed");
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = context_->instance();
  info.PhysicalDevice = context_->physicalDevice();
  info.Device = context_->device();
  info.QueueFamily = context_->queueFamily();
  info.Queue = context_->queue();
  info.DescriptorPool = imgui_pool_;
  info.MinImageCount = std::max(2u, swapchain_->imageCount());
  info.ImageCount = std::max(2u, swapchain_->imageCount());
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = checkImguiVk;
  if (!ImGui_ImplVulkan_Init(&info, swapchain_->overlayPass()))
    return Status::error("ImGui Vulkan backend failed");
  imgui_ready_ = true;
  RDM_TRY(context_->submitAndWait(
      [](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); }));
  ImGui_ImplVulkan_DestroyFontUploadObjects();
  return Status();
}

Status WindowApp::run() {
  while (!glfwWindowShouldClose(window_)) {
    RDM_TRY(frame());
    if (options_.frames > 0 && frames_shown_ >= options_.frames) break;
  }
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  if (!options_.screenshot_png.empty()) {
    auto image = renderer_->readLdr();
    if (!image) return image.status();
    RDM_TRY(writeImage8Png(options_.screenshot_png, *image));
    std::printf("screenshot: %s (%dx%d) after %d frame(s)\n", options_.screenshot_png.c_str(),
                image->width, image->height, frames_shown_);
  }
  return Status();
}

bool WindowApp::waitForWork() {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const bool scripted = options_.frames > 0;  // --frames N renders N frames back to back
  const bool busy = (live_ && live_->state().busy) || reference_.busy();
  if (renderer_->accumulation().refining()) redraw_ = true;  // the still view's average
  if (scripted || redraw_ || since(last_input_) < kSettleSeconds) {
    glfwPollEvents();
  } else {
    glfwWaitEventsTimeout(busy ? kProgressSeconds : 1.0);
  }
  if (input_.count() != input_seen_) input_seen_ = input_.count(), last_input_ = Clock::now();
  if (busy && since(last_progress_draw_) >= kProgressSeconds) redraw_ = true;
  const bool draw = scripted || redraw_ || since(last_input_) < kSettleSeconds;
  if (draw) redraw_ = false, last_progress_draw_ = Clock::now();
  return draw;
}

void WindowApp::applyLiveUpdates() {
  while (auto update = live_->takeAtlas()) {
    if (Status s = applyLiveAtlas(*renderer_, *update); !s.ok()) {
      panel_.message = "live update refused (keeping the last atlas): " + s.message();
      continue;
    }
    std::printf("live: job %s pass %d/%d%s: %zu RDM rect(s)\n", update->job.c_str(),
                update->pass + 1, update->passes, update->final ? " (final)" : " (preview)",
                update->is_delta ? update->updates.size() : update->atlas.layout.entries.size());
    std::fflush(stdout);
    redraw_ = true;
  }
}

void WindowApp::drawOverlays() {
  StatusBarState bar;
  std::vector<OutlineBox> boxes;
  if (live_) {
    const LiveState live = live_->state();
    bar.live = true, bar.daemon = daemon_, bar.connected = live.connected, bar.busy = live.busy;
    bar.job = live.job, bar.mode = live.mode, bar.message = live.message;
    bar.pass = live.pass, bar.passes = live.passes, bar.fraction = live.fraction;
    bar.eta_seconds = live.eta_seconds;
    bar.stale_blocks = int(live.stale_slots.size());
    bar.preview_rdms = live.preview_rdms, bar.phase = live.phase;
    bar.has_atlas = !renderer_->layout().entries.empty();
    for (const glm::ivec3& s : live.stale_slots) boxes.push_back(staleBox(s));
  } else {
    bar.message = panel_.message;
  }
  if (panel_.hover.hit && panel_.tool != EditTool::kNone) {
    const bool voxel = panel_.tool == EditTool::kCarveVoxel || panel_.tool == EditTool::kPaintVoxel;
    boxes.push_back(hoverBox(panel_.hover, voxel, voxel ? panel_.brush_radius : 0));
  }
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  if (auto basis = cameraBasis(camera_.camera()); basis && display.x > 0 && display.y > 0)
    drawOutlines(boxes, viewProjection(*basis, display.x / display.y), display.x, display.y);
  const StatusBarRequests requests = drawStatusBar(bar);
  if (requests.cancel && live_) live_->requestCancel();
  if (requests.bake) {
    if (!live_)
      live_ = std::make_unique<LocalRebake>(options_.live_mode, std::exchange(local_seed_, {}));
    live_->requestRebake(editor_->scene());
  }
}

Status WindowApp::frame() {
  if (live_) applyLiveUpdates();
  pollPrediction();
  RDM_TRY(pollReference());
  // Interactive resolution while a rebake shares the CPU; back to full when it is done.
  const int divisor = live_ && live_->state().busy ? options_.live_divisor : 1;
  if (divisor != renderer_->resolutionDivisor())
    renderer_->setResolutionDivisor(divisor), redraw_ = true;
  if (!waitForWork()) return Status();
  const auto now = std::chrono::steady_clock::now();
  const float dt = std::chrono::duration<float>(now - last_time_).count();
  last_time_ = now;
  panel_.frame_ms = 1e3 * dt;
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window_, &fb_w, &fb_h);
  if (fb_w == 0 || fb_h == 0) {  // minimised: what was pressed meanwhile is not applied later
    input_.takeEvents();
    return Status();
  }
  if (resize_pending_ || uint32_t(fb_w) != swapchain_->extent().width ||
      uint32_t(fb_h) != swapchain_->extent().height) {
    RDM_TRY(swapchain_->create(fb_w, fb_h));
    RDM_TRY(renderer_->resize(int(swapchain_->extent().width), int(swapchain_->extent().height)));
    resize_pending_ = false;
  }
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  const PanelRequests requests = drawPanel(panel_, *editor_);
  drawOverlays();
  drawReferenceDivider();
  ImGui::Render();
  RDM_TRY(handleRequests(requests));
  camera_.setMode(panel_.camera_mode);
  updateCamera(dt);
  updateHover();
  RDM_TRY(consumeInput());
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  uint32_t index = 0;
  bool out_of_date = false;
  RDM_TRY(swapchain_->acquire(acquired_, index, out_of_date));
  if (out_of_date) {
    resize_pending_ = true;
    return Status();
  }
  RDM_TRY(recordAndSubmit(index));
  RDM_TRY(swapchain_->present(finished_, index, out_of_date));
  resize_pending_ = out_of_date;
  ++frames_shown_;
  finishFrameTime(now);
  return Status();
}

void WindowApp::finishFrameTime(std::chrono::steady_clock::time_point start) {
  if (options_.min_frame_ms <= 0) return;
  std::this_thread::sleep_until(start + std::chrono::milliseconds(options_.min_frame_ms));
}

Status WindowApp::recordAndSubmit(uint32_t index) {
  RDM_VK_TRY(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  RDM_VK_TRY(vkBeginCommandBuffer(cmd_, &begin));
  RDM_TRY(renderer_->recordFrame(cmd_, camera_.camera(), panel_.terms));
  const VkImage target = swapchain_->image(index);
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = target;
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &barrier);
  const VkExtent2D e = swapchain_->extent();
  VkImageBlit blit{};
  blit.srcSubresource = blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  blit.srcOffsets[1] = {renderer_->width(), renderer_->height(), 1};
  blit.dstOffsets[1] = {int32_t(e.width), int32_t(e.height), 1};
  vkCmdBlitImage(cmd_, renderer_->ldrImage().handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
  recordReferenceCopy(cmd_, target);
  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  pass.renderPass = swapchain_->overlayPass();
  pass.framebuffer = swapchain_->framebuffer(index);
  pass.renderArea = {{0, 0}, e};
  vkCmdBeginRenderPass(cmd_, &pass, VK_SUBPASS_CONTENTS_INLINE);
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd_);
  vkCmdEndRenderPass(cmd_);
  RDM_VK_TRY(vkEndCommandBuffer(cmd_));
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &acquired_;
  submit.pWaitDstStageMask = &wait_stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &finished_;
  RDM_VK_TRY(vkResetFences(context_->device(), 1, &fence_));
  RDM_VK_TRY(vkQueueSubmit(context_->queue(), 1, &submit, fence_));
  return Status();
}

WindowApp::~WindowApp() {
  if (context_) vkDeviceWaitIdle(context_->device());
  if (imgui_ready_) {
    ImGui_ImplVulkan_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  live_.reset();
  if (context_) {
    const VkDevice device = context_->device();
    if (imgui_pool_ != VK_NULL_HANDLE) vkDestroyDescriptorPool(device, imgui_pool_, nullptr);
    for (VkSemaphore s : {acquired_, finished_}) {
      if (s != VK_NULL_HANDLE) vkDestroySemaphore(device, s, nullptr);
    }
    if (fence_ != VK_NULL_HANDLE) vkDestroyFence(device, fence_, nullptr);
    if (cmd_ != VK_NULL_HANDLE) vkFreeCommandBuffers(device, context_->commandPool(), 1, &cmd_);
  }
  swapchain_.reset();
  renderer_.reset();
  context_.reset();
  if (window_) glfwDestroyWindow(window_);
  if (glfw_ready_) glfwTerminate();
}

int runWindow(const ViewerOptions& options) {
  WindowApp app(options);
  Status status = app.init();
  if (status.ok()) status = app.run();
  if (!status.ok()) return std::fprintf(stderr, "rdm-viewer: %s\n", status.message().c_str()), 1;
  return 0;
}

}  // namespace rdm::viewer
