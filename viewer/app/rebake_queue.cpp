#include "rebake_queue.h"

#include <exception>
#include <utility>

namespace rdm::viewer {

std::optional<Scene> RebakeQueue::waitForRequest(std::unique_lock<std::mutex>& lock) {
  live.busy = false;
  wake.wait(lock, [&] { return stop || pending.has_value(); });
  if (stop) return std::nullopt;
  std::optional<Scene> scene = std::move(pending);
  pending.reset();
  live.busy = true;
  return scene;
}

void RebakeQueue::setMessage(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex);
  live.message = message;
}

std::optional<LiveAtlas> RebakeQueue::takeAtlas() {
  std::lock_guard<std::mutex> lock(mutex);
  if (ready.empty()) return std::nullopt;
  std::optional<LiveAtlas> out = std::move(ready.front());
  ready.pop_front();
  return out;
}

LiveState RebakeQueue::state() {
  std::lock_guard<std::mutex> lock(mutex);
  return live;
}

void RebakeQueue::startWorker(std::function<void()> run, std::string error_prefix) {
  worker_ = std::thread([this, run = std::move(run), error_prefix = std::move(error_prefix)] {
    try {
      run();
    } catch (const std::exception& e) {
      setMessage(error_prefix + e.what());
    }
  });
}

void RebakeQueue::stopWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
  }
  wake.notify_all();
  if (worker_.joinable()) worker_.join();
}

}  // namespace rdm::viewer
