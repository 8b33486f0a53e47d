#include "rdm/base/thread_priority.h"

#include <gtest/gtest.h>

#include <thread>

#if defined(__linux__)
#include <sys/resource.h>
#include <unistd.h>

namespace rdm {
namespace {

int threadNice() {
  return getpriority(PRIO_PROCESS, id_t(gettid()));
}

TEST(ThreadPriority, LowersOnlyTheCallingThreadAndItsChildren) {
  const int before = threadNice();
  int lowered = -100, child = -100;
  std::thread worker([&] {
    lowerThreadPriority();
    lowered = threadNice();
    std::thread([&] { child = threadNice(); }).join();  // threads inherit the creator's nice
  });
  worker.join();
  EXPECT_EQ(lowered, std::max(before, kBackgroundNice));
  EXPECT_EQ(child, lowered);
  EXPECT_EQ(threadNice(), before);
}

}  // namespace
}  // namespace rdm
#endif
