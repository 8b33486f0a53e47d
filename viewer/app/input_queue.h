// Discrete input of the window (key presses with their modifiers, mouse button presses and
// releases with the cursor where they happened), queued by the GLFW callbacks in arrival order
// and taken once per frame: a press and its release that both fall between two frames still
// count, however long a frame takes (0.6-1.3 s on lavapipe). Continuous input (held camera
// keys, drags) stays polled. Header-only; the callbacks and the frame run on the main thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace rdm::viewer {

struct InputEvent {
  enum class Kind { kKey, kButton };
  Kind kind = Kind::kKey;
  int code = 0;            // GLFW_KEY_* or GLFW_MOUSE_BUTTON_*
  int action = 0;          // GLFW_PRESS, GLFW_RELEASE or GLFW_REPEAT
  int mods = 0;            // GLFW_MOD_* bits held at the event
  glm::dvec2 cursor{0.0};  // window coordinates (screen pixels) at the event
};

// Events past this many untaken are dropped (a window that draws no frame, e.g. minimised).
inline constexpr size_t kMaxQueuedInputEvents = 1024;

class InputQueue {
 public:
  void key(int code, int action, int mods) { push(InputEvent::Kind::kKey, code, action, mods); }
  void button(int code, int action, int mods) {
    push(InputEvent::Kind::kButton, code, action, mods);
  }
  void cursorMoved(glm::dvec2 cursor) { cursor_ = cursor, ++count_; }
  void scrolled(float dy) { scroll_ += dy, ++count_; }
  void touched() { ++count_; }  // input that is not queued: characters, resize, refresh

  // The events since the last take, oldest first.
  std::vector<InputEvent> takeEvents() { return std::exchange(events_, {}); }
  float takeScroll() { return std::exchange(scroll_, 0.0f); }
  // Changes with every input of any kind (the window renders on demand after input).
  uint64_t count() const { return count_; }

 private:
  void push(InputEvent::Kind kind, int code, int action, int mods) {
    ++count_;
    if (events_.size() < kMaxQueuedInputEvents)
      events_.push_back({kind, code, action, mods, cursor_});
  }

  std::vector<InputEvent> events_;
  glm::dvec2 cursor_{0.0};  // from the cursor callbacks, so in order with the buttons
  float scroll_ = 0.0f;
  uint64_t count_ = 0;
};

}  // namespace rdm::viewer
