// Keeps each submission of the bake kernel near a wall-time budget (docs/vulkan.md, "Dispatch
// budget"), so a heavy unit never holds the device past a driver's timeout (Windows resets a
// GPU after 2 s by default). Two knobs, both free for the result, since a path suspends and
// resumes bit for bit and batches split anywhere: the loop budget of one dispatch (how far
// each path may walk before it saves its state) and the texel jobs of one batch. A dispatch
// over the budget halves the loop budget, then, at its floor, the batch; one under a quarter
// of it doubles the batch back, then the loop budget.
#pragma once

#include <algorithm>
#include <cstdint>

namespace rdm {

class DispatchBudget {
 public:
  static constexpr uint32_t kMinLoopBudget = 256;
  static constexpr uint32_t kStartLoopBudget = 4096;

  // `seconds` <= 0: no budget (the largest loop budget and batch throughout).
  DispatchBudget(double seconds, uint32_t max_loop_budget, uint32_t max_jobs)
      : seconds_(seconds),
        max_loop_(max_loop_budget),
        max_jobs_(max_jobs),
        loop_(seconds > 0 ? std::min(max_loop_budget, kStartLoopBudget) : max_loop_budget),
        jobs_(max_jobs) {}

  uint32_t loopBudget() const { return loop_; }
  uint32_t maxJobs() const { return jobs_; }

  // After a dispatch that ran `elapsed` seconds.
  void observe(double elapsed) {
    if (seconds_ <= 0) return;
    if (elapsed > seconds_) {
      if (loop_ > kMinLoopBudget) {
        loop_ = std::max(kMinLoopBudget, loop_ / 2);
      } else {
        jobs_ = std::max(1u, jobs_ / 2);
      }
    } else if (elapsed < 0.25 * seconds_) {
      if (jobs_ < max_jobs_) {
        jobs_ = std::min(max_jobs_, jobs_ * 2);
      } else {
        loop_ = std::min(max_loop_, loop_ * 2);
      }
    }
  }

 private:
  const double seconds_;
  const uint32_t max_loop_, max_jobs_;
  uint32_t loop_, jobs_;
};

}  // namespace rdm
