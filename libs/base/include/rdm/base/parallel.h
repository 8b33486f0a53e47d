// The core's one parallel loop, for the bake's units, the render's rows and FLIP's two
// images. Indices are handed out one at a time in increasing order from a shared counter,
// so a worker that finishes takes the next: the right balance for items of very different
// cost (a unit of an S = 128 face beside one of S = 2). Results must not depend on which
// worker ran an index; the callers write each index's output to its own place.
//
// Not oneTBB: Debian's libtbb is not built for ThreadSanitizer, whose pass over the core
// (scripts/test.sh) then reports TBB's own hand-offs as races (docs/dependencies.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>

namespace rdm {

struct ParallelOptions {
  int threads = 0;  // workers; 0: one per hardware thread
  // Called on the calling thread every `tick_seconds` while workers run, and once more
  // after they finish: the one thread that reports progress.
  std::function<void()> on_tick;
  double tick_seconds = 0.02;
};

// Calls body(i) for every i in [0, count) on options.threads worker threads, or inline on
// the calling thread when one worker suffices (threads == 1 or count <= 1) and no tick is
// asked for. body returns false to stop: indices not yet started are then skipped.
// An exception from body stops the loop the same way and is rethrown here, on the caller,
// once every worker has returned. Returns the number of indices that ran.
size_t parallelFor(size_t count, const ParallelOptions& options,
                   const std::function<bool(size_t)>& body);

// options.threads resolved: at least 1.
int workerCount(int threads);

// CPU time the calling thread has used, in nanoseconds (CLOCK_THREAD_CPUTIME_ID): a cost
// that the load of a shared machine changes far less than wall time.
uint64_t threadCpuNanoseconds();

}  // namespace rdm
