#include "rdm/base/parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <ctime>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace rdm {

int workerCount(int threads) {
  return threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
}

uint64_t threadCpuNanoseconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return uint64_t(t.tv_sec) * 1000000000u + uint64_t(t.tv_nsec);
}

namespace {

// What the workers share; the mutex guards `error` and `workers_left`.
struct LoopState {
  std::atomic<size_t> next{0}, ran{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable finished;
  int workers_left = 0;
  std::exception_ptr error;
};

void runWorker(size_t count, const std::function<bool(size_t)>& body, LoopState& s) {
  try {
    for (size_t i; !s.stop.load() && (i = s.next.fetch_add(1)) < count;) {
      s.ran.fetch_add(1);
      if (!body(i)) s.stop = true;
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (!s.error) s.error = std::current_exception();
    s.stop = true;
  }
  std::lock_guard<std::mutex> lock(s.mutex);
  if (--s.workers_left == 0) s.finished.notify_all();
}

}  // namespace

size_t parallelFor(size_t count, const ParallelOptions& options,
                   const std::function<bool(size_t)>& body) {
  const int workers = int(std::min<size_t>(size_t(workerCount(options.threads)), count));
  if (workers <= 1 && !options.on_tick) {
    size_t ran = 0;
    for (size_t i = 0; i < count; ++i) {
      ++ran;
      if (!body(i)) break;
    }
    return ran;
  }
  LoopState s;
  s.workers_left = workers;
  std::vector<std::thread> threads;
  threads.reserve(size_t(workers));
  for (int t = 0; t < workers; ++t) threads.emplace_back([&] { runWorker(count, body, s); });
  const auto tick = std::chrono::duration<double>(options.tick_seconds);
  {
    std::unique_lock<std::mutex> lock(s.mutex);
    while (!s.finished.wait_for(lock, tick, [&] { return s.workers_left == 0; })) {
      if (!options.on_tick) continue;
      lock.unlock();
      options.on_tick();
      lock.lock();
    }
  }
  for (std::thread& t : threads) t.join();
  if (options.on_tick) options.on_tick();
  if (s.error) std::rethrow_exception(s.error);
  return s.ran.load();
}

}  // namespace rdm
