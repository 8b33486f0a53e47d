// JobManager's threads: the executor (prepare, finish) and the unit workers. Each piece of
// work runs inside a catch: one that throws fails its job and the thread goes on. Which unit
// runs next is UnitScheduler's; what a finished job writes is JobFinisher's.
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "active_job.h"
#include "job_finisher.h"
#include "rdm/base/clock.h"
#include "rdm/base/failpoint.h"
#include "rdm/service/job_manager.h"
#include "unit_scheduler.h"

namespace rdm {

std::optional<size_t> JobManager::nextToPrepare() {
  uint64_t held = 0;
  for (const auto& a : scheduler_->jobs()) held += records_.at(a->id).memory_estimate;
  return records_.nextToPrepare(held, scheduler_->empty(), options_.memory_budget);
}

void JobManager::executorLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    std::optional<size_t> next;
    exec_cv_.wait(
        lock, [&] { return stopping_ || (next = nextToPrepare()) || scheduler_->anyFinishable(); });
    if (stopping_) return;
    if (std::shared_ptr<ActiveJob> done = scheduler_->takeFinishable()) {
      finishNext(lock, std::move(done));
    } else if (next) {
      prepareNext(lock, *next);
    }
  }
}

void JobManager::finishNext(std::unique_lock<std::mutex>& lock, std::shared_ptr<ActiveJob> job) {
  const std::string id = job->id;
  finishing_.insert(id);  // from here on a cancel is refused (JobRecords::cancel)
  lock.unlock();
  finishGuarded(*job);
  job.reset();
  // glibc keeps freed heap in its arenas; a job's peak would otherwise stay resident for
  // the daemon's life.
  malloc_trim(0);
  lock.lock();
  finishing_.erase(id);
}

void JobManager::prepareNext(std::unique_lock<std::mutex>& lock, size_t queued) {
  const std::string id = records_.takeQueued(queued);
  records_.countRun(id);
  const JobRecord record = records_.at(id);
  lock.unlock();
  auto prepared = prepareGuarded(record);
  if (!prepared) {
    failJob(id, prepared.error(), prepared.status().code());
    lock.lock();
    return;
  }
  lock.lock();
  std::shared_ptr<ActiveJob> job = *prepared;
  JobRecord& live = records_.at(id);
  job->cancelled = live.cancel_requested;
  job->cancel_flag = live.cancel_requested;
  live.rdms_done = int(std::count(job->units_left.begin(), job->units_left.end(), 0));
  live.state = JobState::kRunning;
  if (live.started == 0.0) live.started = nowSeconds();
  records_.save(id);
  scheduler_->add(job);
  work_cv_.notify_all();
  exec_cv_.notify_all();
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

Expected<std::shared_ptr<ActiveJob>> JobManager::prepareGuarded(const JobRecord& record) {
  try {
    return prepare(record);
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
  progress_cv_.notify_all();
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
  if (!saved) std::fprintf(stderr, "rdm serve: %s\n", saved.message().c_str());
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
  if (!job.failure.ok()) return failJob(job.id, job.failure.message(), job.failure.code());
  if (job.cancelled) return cancelJob(job.id);
  const auto start = std::chrono::steady_clock::now();
  publish(job, job.passes() - 1, job.settings, {}, job.spill);
  if (Status s = finisher_->finalize(job, record, base); !s) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      published_.erase(job.id);  // the last holder of the spill besides the job
    }
    job.spill.reset();
    return failJob(job.id, s.message(), s.code());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& live = records_.at(job.id);
  records_.end(live, JobState::kSucceeded);
  live.rdms_held_peak = job.storage->peakRdmsHeld();
  live.finalize_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  records_.save(job.id);
  published_.erase(job.id);  // the job's files answer from now on
  progress_cv_.notify_all();
  store_.removeUnits(job.id);
}

}  // namespace rdm
