#include "interrupt.h"

#include <csignal>
#include <cstdio>

namespace rdm::cli {
namespace {

std::atomic<bool> g_interrupted{false};
std::atomic<bool> g_announced{false};
static_assert(std::atomic<bool>::is_always_lock_free);  // set from a signal handler

extern "C" void onInterrupt(int) {
  g_interrupted.store(true);
}

void installHandler(int flags) {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  action.sa_flags = flags;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
}

}  // namespace

const std::atomic<bool>* interruptFlag() {
  return &g_interrupted;
}

bool interrupted() {
  return g_interrupted.load();
}

void stopOnInterrupt() {
  installHandler(SA_RESETHAND);  // the handler resets itself: the second SIGINT is the default's
}

void recordInterrupt() {
  installHandler(0);
}

void announceInterrupt(const char* verb) {
  if (!interrupted() || g_announced.exchange(true)) return;
  std::fprintf(stderr,
               "\nrdm %s: interrupted: finishing the work units in progress, then stopping "
               "without writing (Ctrl-C again to quit at once)\n",
               verb);
}

}  // namespace rdm::cli
