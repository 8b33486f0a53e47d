// JobManager's threads: the dispatcher and the phase threads it starts (prepare, finish) and
// the unit workers. Each piece of work runs inside a catch: one that throws fails its job and
// the thread goes on. Which unit runs next is UnitScheduler's; what a finished job writes is
// JobFinisher's.
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "active_job.h"
#include "job_finisher.h"
#include "rdm/bake/rebake_selection.h"
#include "rdm/base/clock.h"
#include "rdm/base/failpoint.h"
#include "rdm/base/log.h"
#include "rdm/base/thread_priority.h"
#include "rdm/service/job_manager.h"
#include "unit_scheduler.h"

namespace rdm {

namespace {

// Preparations of one kind (incremental, full) at once: a preparation is mostly one thread's
// work and holds a world, so more would only share the cores and the memory.
constexpr int kMaxPreparing = 2;

}  // namespace

std::optional<size_t> JobManager::nextToPrepare() {
  uint64_t held = 0;
  int preparing[2] = {0, 0};  // incremental, full
  for (const auto& a : scheduler_->jobs()) held += records_.at(a->id).memory_estimate;
  for (const auto* phase : {&preparing_, &finishing_})
    for (const auto& [id, job] : *phase) held += records_.at(id).memory_estimate;
  for (const auto& [id, job] : preparing_) preparing[records_.at(id).mode == BakeMode::kFull]++;
  const bool none_running = scheduler_->empty() && preparing_.empty() && finishing_.empty();
  std::optional<size_t> next = records_.nextToPrepare(held, none_running, options_.memory_budget);
  // Incremental jobs come first in the queue: a full job is next only when none of them is.
  if (next &&
      preparing[records_.at(records_.queuedId(*next)).mode == BakeMode::kFull] >= kMaxPreparing)
    return std::nullopt;
  return next;
}

void JobManager::executorLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    std::optional<size_t> next;
    exec_cv_.wait(lock, [&] {
      return stopping_ || !phase_done_.empty() || (next = nextToPrepare()) ||
             scheduler_->anyFinishable();
    });
    if (stopping_) return;  // stop() joins the phase threads
    if (!phase_done_.empty()) {
      reapPhases(lock);
      continue;
    }
    if (std::shared_ptr<ActiveJob> done = scheduler_->takeFinishable()) {
      startFinish(lock, std::move(done));
    } else if (next) {
      startPrepare(lock, *next);
    }
  }
}

void JobManager::reapPhases(std::unique_lock<std::mutex>& lock) {
  std::vector<std::thread> ended;
  for (uint64_t n : phase_done_) {
    auto it = phase_threads_.find(n);
    if (it == phase_threads_.end()) continue;
    ended.push_back(std::move(it->second));
    phase_threads_.erase(it);
  }
  phase_done_.clear();
  lock.unlock();  // an ended task may still be leaving the lock it marked itself done under
  for (std::thread& t : ended) t.join();
  lock.lock();
}

void JobManager::runPhase(std::unique_lock<std::mutex>& lock, std::function<void()> task) {
  const uint64_t n = next_phase_++;
  auto body = [this, n, task] {
    lowerThreadPriority();
    try {
      task();
    } catch (const std::exception& e) {  // the tasks catch their own; this is the last resort
      logEvent(LogLevel::kError, "thread", {{"message", "phase thread: " + std::string(e.what())}});
    }
    std::lock_guard<std::mutex> done(mutex_);
    try {
      phase_done_.push_back(n);
    } catch (const std::exception&) {  // joined at stop() instead
    }
    exec_cv_.notify_all();
  };
  try {
    phase_threads_.emplace(n, std::thread(body));
  } catch (const std::exception& e) {  // no thread to be had: run it here
    logEvent(LogLevel::kError, "thread",
             {{"message",
               "no phase thread (" + std::string(e.what()) + "); running it on the dispatcher"}});
    lock.unlock();
    try {
      task();
    } catch (const std::exception& e2) {
      logEvent(LogLevel::kError, "thread", {{"message", "phase task: " + std::string(e2.what())}});
    }
    lock.lock();
  }
}

void JobManager::startFinish(std::unique_lock<std::mutex>& lock, std::shared_ptr<ActiveJob> job) {
  finishing_[job->id] = job;
  // The task moves the job out, so finishTask holds the last reference and frees it.
  runPhase(lock, [this, job]() mutable { finishTask(std::move(job)); });
}

void JobManager::finishTask(std::shared_ptr<ActiveJob> job) {
  const std::string id = job->id;
  finishGuarded(*job);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finishing_.erase(id);
    ++finishes_done_;
    exec_cv_.notify_all();      // its memory is free for the next preparation
    progress_cv_.notify_all();  // the retention thread now counts it as finished
  }
  job.reset();
  // glibc keeps freed heap in its arenas; a job's peak would otherwise stay resident for
  // the daemon's life.
  malloc_trim(0);
}

void JobManager::startPrepare(std::unique_lock<std::mutex>& lock, size_t queued) {
  const std::string id = records_.takeQueued(queued);
  records_.countRun(id);
  auto job = std::make_shared<ActiveJob>();
  const JobRecord& record = records_.at(id);
  job->id = id, job->mode = record.mode;
  job->abort = record.cancel_requested;
  preparing_[id] = job;
  runPhase(lock, [this, job, record] { prepareTask(job, record); });
}

void JobManager::prepareTask(const std::shared_ptr<ActiveJob>& job, const JobRecord& record) {
  const std::string& id = job->id;
  const Status prepared = prepareGuarded(record, *job);
  std::unique_lock<std::mutex> lock(mutex_);
  preparing_.erase(id);
  exec_cv_.notify_all();
  // A stop leaves the job queued on disk, to be prepared again at the next start.
  if (stopping_) return;
  const bool cancel = records_.at(id).cancel_requested;
  if (!prepared || cancel) {
    lock.unlock();
    if (cancel) return cancelJob(id);
    return failJob(id, prepared.message(), prepared.code());
  }
  JobRecord& live = records_.at(id);
  live.rdms_done = int(std::count(job->units_left.begin(), job->units_left.end(), 0));
  live.state = JobState::kRunning;
  if (live.started == 0.0) live.started = nowSeconds();
  records_.save(id);
  logJobStarted(live);
  scheduler_->add(job);
  work_cv_.notify_all();
}

void JobManager::workerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    std::shared_ptr<ActiveJob> job;
    size_t unit = 0;
    work_cv_.wait(lock, [&] { return stopping_ || scheduler_->pickUnit(job, unit); });
    if (stopping_) return;
    lock.unlock();
    try {
      if (unit & kPreviewUnit) {
        runPreviewUnit(*job, unit & ~kPreviewUnit);
      } else {
        runUnit(*job, unit);
      }
    } catch (const std::exception& e) {
      failInFlight(*job, jobFailure(e, "baking a work unit"));
    }
    lock.lock();
  }
}

Status JobManager::prepareGuarded(const JobRecord& record, ActiveJob& into) {
  try {
    return prepare(record, into);
  } catch (const std::exception& e) {
    return jobFailure(e, "preparing the job");
  }
}

void JobManager::finishGuarded(ActiveJob& job) {
  try {
    finishJob(job);
  } catch (const std::exception& e) {
    const Status s = jobFailure(e, "writing the job's results");
    failJob(job.id, s.message(), s.code());
  }
}

void JobManager::failInFlight(ActiveJob& job, Status failure) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (UnitScheduler::failInFlight(job, std::move(failure))) exec_cv_.notify_all();
}

void JobManager::leaveFlight(ActiveJob& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  job.in_flight--;
  if (job.finishable()) exec_cv_.notify_all();
}

// Preview units are neither checkpointed nor counted in the job's progress; the pass is
// published when its last unit lands.
void JobManager::runPreviewUnit(ActiveJob& job, size_t index) {
  const uint64_t rays = job.preview->session->runUnit(index);
  metrics_.addRays(rays);
  bool last = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last = --job.preview->left == 0 && !job.cancelled;
  }
  // Still in flight, so the job cannot finish (and publish its final pass) before this.
  if (last) publish(job, 0, job.preview->settings, snapshotImages(*job.preview->session));
  leaveFlight(job);
}

void JobManager::publish(const ActiveJob& job, int pass, const BakeSettings& settings,
                         std::map<RdmKey, Image> own, std::shared_ptr<const RdmSpill> spill) {
  auto p = makePublishedPass(job, pass, settings, std::move(own), std::move(spill));
  std::lock_guard<std::mutex> lock(mutex_);
  published_[job.id] = std::move(p);
  JobRecord& record = records_.at(job.id);
  record.passes_done = pass + 1;
  record.pass_seconds.push_back(nowSeconds() - record.created);
  logJobPass(record, pass);
  progress_cv_.notify_all();
}

void JobManager::logJobStarted(const JobRecord& job) {
  logEvent(LogLevel::kInfo, "job",
           {{"id", job.id},
            {"state", "started"},
            {"scene", job.scene_id},
            {"mode", modeName(job.mode)},
            {"seconds", nowSeconds() - job.created}});
}

void JobManager::logJobPass(const JobRecord& job, int pass) {
  logEvent(LogLevel::kInfo, "job",
           {{"id", job.id},
            {"state", "pass"},
            {"scene", job.scene_id},
            {"mode", modeName(job.mode)},
            {"pass", pass},
            {"seconds", nowSeconds() - job.created}});
}

void JobManager::logJobEnd(const JobRecord& job, const std::string& reason) {
  nlohmann::json fields = {{"id", job.id},
                           {"state", stateName(job.state)},
                           {"scene", job.scene_id},
                           {"mode", modeName(job.mode)},
                           {"seconds", job.finished - job.created}};
  if (!reason.empty()) fields["reason"] = reason;
  logEvent(job.state == JobState::kFailed ? LogLevel::kWarn : LogLevel::kInfo, "job", fields);
}

std::shared_ptr<const PublishedPass> JobManager::published(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = published_.find(id);
  return it == published_.end() ? nullptr : it->second;
}

std::optional<JobRecord> JobManager::waitFor(const std::string& id, int passes,
                                             double timeout_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  auto done = [&] {
    const JobRecord* job = records_.find(id);
    return !job || stopping_ || terminal(job->state) || job->passes_done >= passes;
  };
  progress_cv_.wait_until(lock, deadline, done);
  const JobRecord* job = records_.find(id);
  if (!job) return std::nullopt;
  return *job;
}

// Bakes one unit straight into the job's session (texels land in its RDM images; the slot
// sets come back with the unit), persists the unit, then books it under the lock.
void JobManager::runUnit(ActiveJob& job, size_t index) {
  const auto start = std::chrono::steady_clock::now();
  const BakeUnit& u = job.units[index];
  const int local = job.local_index[index];
  UnitSlotSets sets;
  hitFailpoint(Failpoint::kUnitAlloc);
  const uint64_t rays = job.storage->runUnit(index, &sets);
  UnitResult result;
  extractUnit(job.storage->rdms()[size_t(u.rdm)], u, result);
  result.full_set = std::move(sets.full);
  result.first_set = std::move(sets.first);
  result.smooth = sets.smooth_vertex;
  result.rays = rays;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Status saved = store_.saveUnit(job.id, result, local);
  if (!saved) logEvent(LogLevel::kError, "thread", {{"message", saved.message()}});
  metrics_.addRays(rays);
  metrics_.addBakeSeconds(result.seconds);
  std::unique_lock<std::mutex> lock(mutex_);
  if (UnitScheduler::bookUnit(job, index, result, saved, records_.at(job.id))) {
    lock.unlock();
    job.releaseFinished(size_t(u.rdm));
    lock.lock();
  }
  job.in_flight--;
  if (job.finishable()) exec_cv_.notify_all();
}

void JobManager::finishJob(ActiveJob& job) {
  JobRecord record;
  std::optional<JobRecord> base;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    record = records_.at(job.id);
    if (const JobRecord* b = records_.find(record.base_job)) base = *b;
  }
  // A job that ends without results gives its spill file's disk back before it is seen to
  // end (a client told of a full disk may retry at once).
  if (!job.failure.ok() || job.cancelled) job.spill.reset();
  // A cancel the client was told of wins over a failure that came after it.
  if (record.cancel_requested)
    return cancelJob(job.id, job.failure.ok() ? std::string() : job.failure.message());
  if (!job.failure.ok()) return failJob(job.id, job.failure.message(), job.failure.code());
  if (job.cancelled) return cancelJob(job.id);
  const auto start = std::chrono::steady_clock::now();
  publish(job, job.passes() - 1, job.settings, {}, job.spill);
  const Status written = finisher_->finalize(job, record, base, [&](const FaceLightProgress& p) {
    std::lock_guard<std::mutex> progress_lock(mutex_);
    JobRecord& live = records_.at(job.id);
    live.face_light_faces_total = p.faces_total;
    live.face_light_faces_done = p.faces_done;
  });
  std::unique_lock<std::mutex> lock(mutex_);
  JobRecord& live = records_.at(job.id);
  const bool cancel = live.cancel_requested;
  if (!written || cancel) {
    const bool stopped = stopping_;
    published_.erase(job.id);  // the last holder of the spill besides the job
    lock.unlock();
    job.spill.reset();
    store_.removeOutputs(job.id);
    if (cancel) return cancelJob(job.id, written.ok() ? std::string() : written.message());
    if (stopped) return;  // unfinished on disk: resumed at the next start
    return failJob(job.id, written.message(), written.code());
  }
  records_.end(live, JobState::kSucceeded);
  live.rdms_held_peak = job.storage->peakRdmsHeld();
  live.mean_relative_error = job.noise.mean_relative_error;
  live.max_relative_error = job.noise.max_relative_error;
  live.denoise_seconds = job.denoise_seconds;
  live.finalize_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  records_.save(job.id);
  logJobEnd(live);
  published_.erase(job.id);  // the job's files answer from now on
  progress_cv_.notify_all();
  lock.unlock();
  store_.removeUnits(job.id);
}

}  // namespace rdm
