#include "bounded_queue.h"

namespace rdm::server {

BoundedTaskQueue::BoundedTaskQueue(size_t threads, size_t capacity)
    : capacity_(std::max<size_t>(1, capacity)) {
  for (size_t i = 0; i < std::max<size_t>(1, threads); ++i)
    threads_.emplace_back([this] { work(); });
}

BoundedTaskQueue::~BoundedTaskQueue() {
  shutdown();
}

void BoundedTaskQueue::enqueue(std::function<void()> fn) {
  std::unique_lock<std::mutex> lock(mutex_);
  not_full_.wait(lock, [&] { return shutdown_ || tasks_.size() < capacity_; });
  if (shutdown_) return;  // the socket is closed by its owner's destructor path
  tasks_.push_back(std::move(fn));
  not_empty_.notify_one();
}

bool BoundedTaskQueue::tryEnqueue(std::function<void()> fn) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shutdown_ || tasks_.size() >= capacity_) return false;
  tasks_.push_back(std::move(fn));
  not_empty_.notify_one();
  return true;
}

void BoundedTaskQueue::shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_ && threads_.empty()) return;
    shutdown_ = true;
  }
  not_empty_.notify_all();
  not_full_.notify_all();
  for (std::thread& t : threads_) t.join();
  threads_.clear();
}

void BoundedTaskQueue::work() {
  while (true) {
    std::function<void()> fn;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      not_empty_.wait(lock, [&] { return shutdown_ || !tasks_.empty(); });
      if (tasks_.empty()) return;  // shut down and drained
      fn = std::move(tasks_.front());
      tasks_.pop_front();
      not_full_.notify_one();
    }
    fn();
  }
}

}  // namespace rdm::server
