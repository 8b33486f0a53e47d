// A worker pool with a bound (cpp-httplib 0.11.4's ThreadPool queues without one): the HTTP
// workers of `rdm serve`. The head reader offers complete requests with tryEnqueue() and
// keeps those no worker can take yet; enqueue() blocks while `capacity` tasks wait.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <httplib.h>

namespace rdm::server {

class BoundedTaskQueue : public httplib::TaskQueue {
 public:
  BoundedTaskQueue(size_t threads, size_t capacity);
  ~BoundedTaskQueue() override;
  void enqueue(std::function<void()> fn) override;
  // Never blocks: false when `capacity` tasks already wait (or after shutdown).
  bool tryEnqueue(std::function<void()> fn);
  void shutdown() override;

 private:
  void work();
  const size_t capacity_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<std::function<void()>> tasks_;
  std::vector<std::thread> threads_;
  bool shutdown_ = false;
};

// Runs each task on the caller's thread: for httplib's accept loop, whose only task is handing
// the socket to the HeadReader (http_server.cpp).
class InlineTaskQueue : public httplib::TaskQueue {
 public:
  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override {}
};

}  // namespace rdm::server
