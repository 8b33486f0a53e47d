#include "rdm/base/thread_priority.h"

#if defined(__linux__)
#include <sys/resource.h>
#include <unistd.h>
#endif

namespace rdm {

void lowerThreadPriority() {
#if defined(__linux__)
  // On Linux, PRIO_PROCESS with a thread id names that thread only. Never raises the priority
  // of a thread that already runs nicer (getpriority's -1 is a valid nice value; errors are
  // ignored like the rest).
  const id_t self = id_t(gettid());
  const int now = getpriority(PRIO_PROCESS, self);
  if (now < kBackgroundNice) (void)setpriority(PRIO_PROCESS, self, kBackgroundNice);
#endif
}

}  // namespace rdm
