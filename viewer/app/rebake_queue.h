// What a rebaker's worker thread shares with the window, for both rebakers (LiveRebake and
// LocalRebake): the latest scene asked for (a newer request replaces a queued one), the
// published updates in order, and the state to show. Every member is guarded by `mutex`.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "live_rebake.h"

namespace rdm::viewer {

class RebakeQueue {
 public:
  std::mutex mutex;
  std::condition_variable wake;
  std::optional<Scene> pending;
  std::deque<LiveAtlas> ready;  // in order: each update starts where the previous ended
  LiveState live;
  bool stop = false;

  // With `lock` held on `mutex`: marks the queue idle, waits for a request or stop, and
  // returns the scene to bake (marked busy), nullopt on stop. `lock` stays held.
  std::optional<Scene> waitForRequest(std::unique_lock<std::mutex>& lock);
  void setMessage(const std::string& message);
  std::optional<LiveAtlas> takeAtlas();
  LiveState state();

  // Runs `run` on the worker thread; an exception it lets out ends the worker with
  // `error_prefix` and its message as the state's message, never the process.
  void startWorker(std::function<void()> run, std::string error_prefix);
  // Sets stop, wakes the worker and joins it.
  void stopWorker();

 private:
  std::thread worker_;
};

}  // namespace rdm::viewer
