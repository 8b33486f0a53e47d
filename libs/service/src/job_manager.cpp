#include "rdm/service/job_manager.h"

#include <chrono>
#include <cstdio>
#include <new>
#include <thread>

#include "active_job.h"
#include "job_finisher.h"
#include "rdm/base/parallel.h"
#include "rdm/base/thread_priority.h"
#include "unit_scheduler.h"

namespace rdm {
namespace {

// Runs a thread's loop until it returns. An exception that escaped the loop's own catches
// (one raised while failing a job, when memory is still short) is logged and the loop
// entered again after a pause, so the thread never takes the process down.
template <class Loop>
void runGuarded(const char* thread, Loop loop) {
  while (true) {
    try {
      loop();
      return;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rdm serve: %s thread: %s; going on\n", thread, e.what());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
}

// Starts a thread that runs `loop` at a lowered priority under runGuarded.
template <class Loop>
std::thread guardedThread(const char* name, Loop loop) {
  return std::thread([name, loop] {
    lowerThreadPriority();
    runGuarded(name, loop);
  });
}

}  // namespace

Status jobFailure(const std::exception& e, const std::string& doing) {
  std::fprintf(stderr, "rdm serve: exception while %s: %s\n", doing.c_str(), e.what());
  if (dynamic_cast<const std::bad_alloc*>(&e)) {
    return Status::error(StatusCode::kTooLarge,
                         "out of memory while " + doing + " (" + e.what() +
                             "); submit it with a smaller settings.max_hemisphere, "
                             "\"radiance\": \"half\" or the scene in smaller parts");
  }
  return Status::error("exception while " + doing + ": " + e.what());
}

JobManager::JobManager(JobManagerOptions options, SceneStore& scenes, JobStore& store,
                       Metrics& metrics)
    : options_(options),
      scenes_(scenes),
      store_(store),
      metrics_(metrics),
      records_(scenes, store, metrics),
      scheduler_(std::make_unique<UnitScheduler>()),
      finisher_(std::make_unique<JobFinisher>(scenes, store, options.threads)) {}

JobManager::~JobManager() {
  stop();
}

Status JobManager::start() {
  if (Status s = startBackend(); !s) return s;
  if (Status s = store_.init(); !s) return s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    records_.restore(store_.loadAll());
  }
  executor_ = guardedThread("executor", [this] { executorLoop(); });
  for (int t = 0; t < workerCount(options_.threads); ++t)
    workers_.push_back(guardedThread("bake worker", [this] { workerLoop(); }));
  if (vulkan_) vulkan_worker_ = guardedThread("Vulkan worker", [this] { vulkanWorkerLoop(); });
  return {};
}

void JobManager::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  work_cv_.notify_all();
  exec_cv_.notify_all();
  progress_cv_.notify_all();
  if (executor_.joinable()) executor_.join();
  for (std::thread& t : workers_) t.join();
  workers_.clear();
  if (vulkan_worker_.joinable()) vulkan_worker_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  records_.giveBackRuns();
}

Expected<JobRecord> JobManager::submit(const SubmitRequest& req) {
  auto job = records_.draft(req);
  if (!job) return job;
  if (Status s = assignBackend(*job); !s) return s;
  std::lock_guard<std::mutex> lock(mutex_);
  auto admitted = records_.admit(req, std::move(*job), options_.max_jobs);
  if (admitted) exec_cv_.notify_all();
  return admitted;
}

std::optional<JobRecord> JobManager::get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const JobRecord* job = records_.find(id);
  if (!job) return std::nullopt;
  return *job;
}

std::vector<JobRecord> JobManager::list() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return records_.list();
}

Expected<JobRecord> JobManager::cancel(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto job = records_.cancel(id, finishing_.count(id) > 0);
  if (!job) return job;
  scheduler_->cancel(id);
  exec_cv_.notify_all();
  progress_cv_.notify_all();
  return job;
}

std::set<long long> JobManager::versionsInUse(const std::string& scene_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return records_.versionsInUse(scene_id);
}

JobGauges JobManager::gauges() const {
  std::lock_guard<std::mutex> lock(mutex_);
  JobGauges g;
  records_.countStates(g);
  g.units_pending = scheduler_->pendingUnits();
  return g;
}

void JobManager::failJob(const std::string& id, const std::string& message, StatusCode code) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // A finish that threw after the job had ended.
    if (terminal(records_.at(id).state)) return;
  }
  std::fprintf(stderr, "rdm serve: job %s failed: %s\n", id.c_str(), message.c_str());
  // Partial results go first: on a full disk that frees the space the record needs.
  store_.removeUnits(id);
  store_.removeOutputs(id);
  std::lock_guard<std::mutex> lock(mutex_);
  records_.fail(id, message, code);
  published_.erase(id);
  progress_cv_.notify_all();
}

void JobManager::cancelJob(const std::string& id) {
  store_.removeUnits(id);
  std::lock_guard<std::mutex> lock(mutex_);
  records_.end(records_.at(id), JobState::kCancelled);
  records_.save(id);
  published_.erase(id);
  progress_cv_.notify_all();
}

}  // namespace rdm
