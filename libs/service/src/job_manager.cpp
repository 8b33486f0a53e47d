#include "rdm/service/job_manager.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <new>
#include <thread>

#include "active_job.h"
#include "job_finisher.h"
#include "rdm/base/clock.h"
#include "rdm/base/log.h"
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
      logEvent(
          LogLevel::kError, "job",
          {{"message", std::string(thread) + " thread: " + std::string(e.what()) + "; going on"}});
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
  logEvent(LogLevel::kError, "job",
           {{"message", "exception while " + std::string(doing) + ": " + std::string(e.what())}});
  if (dynamic_cast<const std::bad_alloc*>(&e)) {
    return Status::error(StatusCode::kTooLarge,
                         "out of memory while " + doing + " (" + std::string(e.what()) +
                             "); submit it with a smaller settings.max_hemisphere, "
                             "\"radiance\": \"half\" or the scene in smaller parts");
  }
  return Status::error("exception while " + doing + ": " + std::string(e.what()));
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
  retention_ = guardedThread("retention", [this] { retentionLoop(); });
  return {};
}

void JobManager::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
    for (auto* phase : {&preparing_, &finishing_})
      for (auto& [id, job] : *phase) job->abort = true;
  }
  work_cv_.notify_all();
  exec_cv_.notify_all();
  progress_cv_.notify_all();
  if (executor_.joinable()) executor_.join();
  std::map<uint64_t, std::thread> phases;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    phases.swap(phase_threads_);  // the dispatcher starts no more
  }
  for (auto& [n, t] : phases) t.join();
  for (std::thread& t : workers_) t.join();
  workers_.clear();
  if (vulkan_worker_.joinable()) vulkan_worker_.join();
  if (retention_.joinable()) retention_.join();
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
  // Cancellable until finishJob records the success (it checks cancel_requested under this
  // lock), so `finishing` is never refused.
  auto job = records_.cancel(id, false);
  if (!job) return job;
  scheduler_->cancel(id);
  for (auto* phase : {&preparing_, &finishing_}) {
    if (auto it = phase->find(id); it != phase->end()) it->second->abort = true;
  }
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
  bool cancelled = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // A finish that threw after the job had ended.
    if (terminal(records_.at(id).state)) return;
    cancelled = records_.at(id).cancel_requested;
  }
  if (cancelled) {  // the client was told it is cancelled (202): a later failure keeps that
    store_.removeOutputs(id);
    return cancelJob(id, message);
  }
  logEvent(LogLevel::kError, "job",
           {{"message", "job " + std::string(id) + " failed: " + std::string(message)}});
  // Partial results go first: on a full disk that frees the space the record needs.
  store_.removeUnits(id);
  store_.removeOutputs(id);
  std::lock_guard<std::mutex> lock(mutex_);
  records_.fail(id, message, code);
  logJobEnd(records_.at(id), message);
  published_.erase(id);
  progress_cv_.notify_all();
}

void JobManager::cancelJob(const std::string& id, const std::string& failure) {
  store_.removeUnits(id);
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& job = records_.at(id);
  records_.end(job, JobState::kCancelled);
  records_.save(id);
  logJobEnd(job, failure);
  published_.erase(id);
  progress_cv_.notify_all();
}

std::vector<bool> JobManager::waitsOver(const std::vector<std::pair<std::string, int>>& waits,
                                        double block_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  if (block_s > 0.0 && !stopping_)
    progress_cv_.wait_for(lock, std::chrono::duration<double>(block_s));
  std::vector<bool> over;
  over.reserve(waits.size());
  for (const auto& [id, passes] : waits) {
    const JobRecord* job = records_.find(id);
    over.push_back(!job || stopping_ || terminal(job->state) || job->passes_done >= passes);
  }
  return over;
}

namespace {

// "a, b and 3 more": ids a message names.
std::string nameIds(const std::vector<std::string>& ids) {
  std::string out;
  const size_t shown = std::min<size_t>(ids.size(), 5);
  for (size_t i = 0; i < shown; ++i) out += (i ? ", " : "") + ids[i];
  if (ids.size() > shown) out += " and " + std::to_string(ids.size() - shown) + " more";
  return out;
}

}  // namespace

Status JobManager::trashJobLocked(const std::string& id) {
  const JobRecord* job = records_.find(id);
  if (!job) return Status::notFound("no job '" + id + "'");
  if (!terminal(job->state) || finishing_.count(id)) {
    return Status::conflict("job " + id + " has not finished (" + stateName(job->state) +
                            "): cancel it first (DELETE /v1/jobs/" + id + " cancels it)");
  }
  const std::vector<std::string> needed_by = records_.dependents(id);
  if (!needed_by.empty()) {
    return Status::conflict("job " + id + " is needed by job" +
                            (needed_by.size() > 1 ? "s " : " ") + nameIds(needed_by) +
                            ": their results copy RDMs it baked, or they are incremental jobs "
                            "based on it; delete those first");
  }
  if (Status s = store_.trashJob(id); !s) return s;
  records_.erase(id);
  last_fetch_.erase(id);
  published_.erase(id);
  return {};
}

void JobManager::awaitFinishers(std::unique_lock<std::mutex>& lock,
                                const std::vector<std::string>& ids) {
  // An ended job's finisher still removes its unit files; that takes milliseconds.
  auto left = [&] {
    for (const std::string& id : ids) {
      const JobRecord* job = records_.find(id);
      if (job && terminal(job->state) && finishing_.count(id)) return false;
    }
    return true;
  };
  progress_cv_.wait_for(lock, std::chrono::seconds(10), left);
}

Status JobManager::removeJob(const std::string& id, const char* why) {
  std::string scene;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    awaitFinishers(lock, {id});
    if (const JobRecord* job = records_.find(id)) scene = job->scene_id;
    if (Status s = trashJobLocked(id); !s) return s;
  }
  store_.removeTrashed(id);
  logEvent(LogLevel::kInfo, "job", {{"id", id}, {"state", why}, {"scene", scene}});
  return {};
}

Status JobManager::removeScene(const std::string& scene_id, bool with_jobs) {
  std::vector<std::string> removed;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!scenes_.info(scene_id)) return Status::notFound("no scene '" + scene_id + "'");
    awaitFinishers(lock, records_.sceneJobs(scene_id));
    const std::vector<std::string> jobs = records_.sceneJobs(scene_id);
    std::vector<std::string> unfinished;
    for (const std::string& id : jobs)
      if (!terminal(records_.find(id)->state) || finishing_.count(id)) unfinished.push_back(id);
    if (!unfinished.empty()) {
      return Status::conflict("scene " + scene_id + " has unfinished jobs: " + nameIds(unfinished) +
                              "; cancel them (DELETE /v1/jobs/{id}) and delete the scene again");
    }
    if (!jobs.empty() && !with_jobs) {
      return Status::conflict("scene " + scene_id + " has " + std::to_string(jobs.size()) +
                              " finished job" + (jobs.size() > 1 ? "s" : "") + " kept (" +
                              nameIds(jobs) + "); delete them first, or send DELETE /v1/scenes/" +
                              scene_id + "?jobs=delete to delete them with the scene");
    }
    // Newest first, so no job is ever left needing a deleted one. A failure leaves the scene
    // and the jobs not yet deleted whole.
    for (auto id = jobs.rbegin(); id != jobs.rend(); ++id) {
      if (Status s = trashJobLocked(*id); !s) {
        for (const std::string& gone : removed) store_.removeTrashed(gone);
        return s;
      }
      removed.push_back(*id);
    }
    // Under mutex_: no job is admitted for the scene meanwhile (JobRecords::admit checks it).
    if (Status s = scenes_.remove(scene_id); !s) {
      for (const std::string& gone : removed) store_.removeTrashed(gone);
      return s;
    }
  }
  for (const std::string& id : removed) {
    store_.removeTrashed(id);
    logEvent(LogLevel::kInfo, "job", {{"id", id}, {"state", "deleted"}, {"scene", scene_id}});
  }
  logEvent(LogLevel::kInfo, "scene",
           {{"id", scene_id}, {"state", "deleted"}, {"jobs_deleted", removed.size()}});
  return {};
}

Status JobManager::removeSceneVersion(const std::string& scene_id, long long version) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!scenes_.info(scene_id)) return Status::notFound("no scene '" + scene_id + "'");
    if (records_.versionsInUse(scene_id).count(version)) {
      std::vector<std::string> users;
      for (const std::string& id : records_.sceneJobs(scene_id)) {
        const JobRecord& j = *records_.find(id);
        const JobRecord* base = records_.find(j.base_job);
        if (j.scene_version == version || (base && base->scene_version == version))
          users.push_back(id);
      }
      return Status::conflict(
          "version " + std::to_string(version) + " of scene " + scene_id +
          " is needed: an unfinished job bakes at it or diffs against it, or it is the version "
          "of the scene's newest job that can be a base (jobs at it: " +
          nameIds(users) + ")");
    }
    // Under mutex_: no job is admitted at this version meanwhile (JobRecords::admit checks it).
    if (Status s = scenes_.removeVersion(scene_id, version); !s) return s;
  }
  logEvent(LogLevel::kInfo, "scene",
           {{"id", scene_id}, {"version", version}, {"state", "deleted"}});
  return {};
}

void JobManager::noteFetched(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (records_.find(id)) last_fetch_[id] = nowSeconds();
}

bool JobManager::fetchedRecently(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = last_fetch_.find(id);
  return it != last_fetch_.end() && nowSeconds() - it->second < options_.retention.fetch_grace_s;
}

std::vector<std::string> JobManager::runRetention() {
  const RetentionPolicy& policy = options_.retention;
  std::vector<std::string> expired;
  if (policy.keep_jobs <= 0 && policy.max_data_bytes == 0) return expired;
  while (true) {  // expiring a job may free older ones it needed
    std::vector<RetentionCandidate> finished;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const std::set<std::string> pinned = records_.pinned();
      for (const JobRecord& j : records_.list()) {
        if (!terminal(j.state) || finishing_.count(j.id)) continue;
        auto fetched = last_fetch_.find(j.id);
        finished.push_back({j.id, j.seq, 0, pinned.count(j.id) > 0,
                            fetched == last_fetch_.end() ? 0.0 : fetched->second});
      }
    }
    uint64_t data_bytes = 0;
    if (policy.max_data_bytes > 0) {  // outside the lock: walks the data directory
      data_bytes = store_.dataBytes();
      if (data_bytes > policy.max_data_bytes)
        for (RetentionCandidate& c : finished) c.bytes = store_.jobBytes(c.id);
    }
    size_t gone = 0;
    for (const std::string& id : chooseExpired(finished, data_bytes, policy, nowSeconds())) {
      if (fetchedRecently(id)) continue;    // fetched while the directory was walked
      if (removeJob(id, "expired").ok()) {  // checked again under the lock: pins may change
        expired.push_back(id);
        ++gone;
      }
    }
    if (gone == 0) return expired;
  }
}

void JobManager::retentionLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  // A job counts once it has ended and left finishing_, in either order.
  auto events = [&] { return records_.ended() + finishes_done_; };
  uint64_t seen = events() + 1;  // differs: a run at start
  while (true) {
    progress_cv_.wait(lock, [&] { return stopping_ || events() != seen; });
    if (stopping_) return;
    seen = events();
    lock.unlock();
    runRetention();
    lock.lock();
  }
}

}  // namespace rdm
