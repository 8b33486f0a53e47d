// The core's parallel loop (rdm/base/parallel.h): every index once, stopping, exceptions carried
// to the caller, and progress ticks on the calling thread.
#include "rdm/base/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace rdm {
namespace {

TEST(Parallel, EveryIndexRunsExactlyOnce) {
  for (int threads : {1, 2, 4, 0}) {
    std::vector<std::atomic<int>> runs(1000);
    ParallelOptions options;
    options.threads = threads;
    const size_t ran = parallelFor(runs.size(), options, [&](size_t i) {
      runs[i].fetch_add(1);
      return true;
    });
    EXPECT_EQ(ran, runs.size());
    for (size_t i = 0; i < runs.size(); ++i) ASSERT_EQ(runs[i].load(), 1) << i << " " << threads;
  }
  EXPECT_EQ(parallelFor(0, ParallelOptions{}, [](size_t) { return true; }), 0u);
}

TEST(Parallel, OneWorkerRunsInOrderOnTheCaller) {
  std::vector<size_t> order;
  ParallelOptions options;
  options.threads = 1;
  const auto caller = std::this_thread::get_id();
  parallelFor(50, options, [&](size_t i) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    order.push_back(i);
    return true;
  });
  ASSERT_EQ(order.size(), 50u);
  for (size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], i);
}

// A false return stops handing out indices: those already taken finish (at most one per
// worker beyond the stopping one), the rest never start.
TEST(Parallel, FalseStopsTheLoop) {
  std::atomic<int> calls{0};
  ParallelOptions options;
  options.threads = 4;
  const size_t ran = parallelFor(100000, options, [&](size_t i) {
    ++calls;
    return i < 10;
  });
  EXPECT_EQ(ran, size_t(calls.load()));
  EXPECT_GE(ran, 11u);
  EXPECT_LE(ran, 11u + 2 * 4);
}

TEST(Parallel, AnExceptionReachesTheCallerAfterEveryWorkerReturned) {
  std::atomic<int> running{0};
  ParallelOptions options;
  options.threads = 3;
  EXPECT_THROW(parallelFor(1000, options,
                           [&](size_t i) {
                             ++running;
                             std::this_thread::sleep_for(std::chrono::microseconds(50));
                             --running;
                             if (i == 7) throw std::runtime_error("unit 7");
                             return true;
                           }),
               std::runtime_error);
  EXPECT_EQ(running.load(), 0);  // nothing still running when the exception arrived
}

TEST(Parallel, TicksComeFromTheCallingThreadAndOnceAtTheEnd) {
  const auto caller = std::this_thread::get_id();
  std::atomic<int> done{0};
  int ticks = 0, last_seen = -1;
  ParallelOptions options;
  options.threads = 2;
  options.tick_seconds = 0.001;
  options.on_tick = [&] {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    ++ticks, last_seen = done.load();
  };
  parallelFor(20, options, [&](size_t) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ++done;
    return true;
  });
  EXPECT_GE(ticks, 2);       // during the ~20 ms of work, and the final one
  EXPECT_EQ(last_seen, 20);  // the final tick sees everything done
}

}  // namespace
}  // namespace rdm
