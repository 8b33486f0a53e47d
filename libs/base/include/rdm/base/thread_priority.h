// Background work yields the CPU to interactive work on the same machine: the daemon's bake
// threads and the viewer's in-process bake run below the viewer's render threads, so an
// update's frame is not slowed by the pass baking behind it (docs/performance.md, "Live
// rebakes").
#pragma once

namespace rdm {

// Nice value of background bake threads (Linux: per thread; 19 is the lowest priority).
// At 10 the CFS weight is 110 against 1024 at 0: a busy interactive thread gets about 90 % of
// a contended core, and an idle machine runs the bake at full speed.
constexpr int kBackgroundNice = 10;

// Lowers the calling thread to kBackgroundNice (never raises it). Best effort: where the platform
// has no per-thread priority, or it cannot be changed, the thread runs on unchanged.
void lowerThreadPriority();

}  // namespace rdm
