// Long polls parked without a thread (docs/api.md, "Long polls"): a complete head of
// `GET /v1/jobs/{id}?wait=S[&passes=N]` waits here, costing its buffer and descriptor, until
// the job reaches what it waits for or S seconds pass. It then goes to a worker as the same
// request with `wait=0`, which answers the job's state at once. stop() hands every parked
// request to the workers together, so a daemon's stop never waits for a long poll.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "head_reader.h"

namespace rdm::server {

struct LongPoll {
  std::string job_id;
  int passes = 1 << 20;  // without passes=: until the job ends
  int wait_s = 0;
  size_t wait_value_pos = 0, wait_value_len = 0;  // of S in the request line
};

// The long poll a complete head asks for, when it is one the parker may hold: GET of
// /v1/jobs/{id} with wait in [1, 30] and passes (if any) in [1, 16]; anything else (a value
// out of range, a bad token) goes to a worker, which answers it as usual.
std::optional<LongPoll> parseLongPoll(const std::string& head);
// Turns the request's `wait=S` into `wait=0` (the same length or shorter: the head only).
void endLongPoll(PendingRequest& request, const LongPoll& poll);
// The value of the first header field `name` (lower case, with its colon) in a head.
std::optional<std::string> headerValue(const std::string& head, const std::string& name);

class LongPollParker {
 public:
  // Whether each (job id, passes) wait is over, blocking up to `block_s` for a change first
  // (JobManager::waitsOver).
  using WaitsOver =
      std::function<std::vector<bool>(const std::vector<std::pair<std::string, int>>&, double)>;
  // Takes the request (its wait already ended) to a worker; may block while workers are full.
  using Release = std::function<void(PendingRequest&)>;
  LongPollParker(size_t max_parked, WaitsOver over, Release release);
  ~LongPollParker();
  LongPollParker(const LongPollParker&) = delete;
  LongPollParker& operator=(const LongPollParker&) = delete;

  void start();
  // False (the request untouched) when `max_parked` requests wait or after stop().
  bool park(PendingRequest& request, const LongPoll& poll);
  size_t parked() const;
  // Releases every parked request and joins the thread; later park() calls refuse.
  void stop();

 private:
  struct Parked {
    PendingRequest request;
    LongPoll poll;
    std::chrono::steady_clock::time_point deadline;
  };
  void loop();
  // Takes out the requests whose wait is over (or all), under no lock of this class.
  std::vector<Parked> takeOver(bool all);

  const size_t max_parked_;
  WaitsOver over_;
  Release release_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Parked> parked_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace rdm::server
