// JobManager's threads: the executor (prepare, finalize) and the unit workers. Each piece of
// work runs inside a catch: one that throws fails its job and the thread goes on.
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iterator>

#include "active_job.h"
#include "rdm/base/failpoint.h"
#include "rdm/service/job_manager.h"

namespace rdm {
namespace {

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

std::shared_ptr<ActiveJob> JobManager::takeFinishable() {
  for (size_t i = 0; i < active_.size(); ++i) {
    if (active_[i]->finishable()) {
      std::shared_ptr<ActiveJob> job = active_[i];
      active_.erase(active_.begin() + long(i));
      return job;
    }
  }
  return nullptr;
}

std::optional<size_t> JobManager::nextToPrepare() {
  // Incremental jobs are prepared first so they overtake queued full bakes.
  std::stable_partition(to_prepare_.begin(), to_prepare_.end(),
                        [&](const std::string& id) { return jobs_[id].mode != BakeMode::kFull; });
  uint64_t held = 0;
  for (const auto& a : active_) held += jobs_[a->id].memory_estimate;
  for (size_t i = 0; i < to_prepare_.size(); ++i) {
    const uint64_t need = jobs_[to_prepare_[i]].memory_estimate;
    if (active_.empty() || options_.memory_budget == 0 || held + need <= options_.memory_budget)
      return i;
  }
  return std::nullopt;
}

void JobManager::executorLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    std::optional<size_t> next;
    exec_cv_.wait(lock, [&] {
      if (stopping_ || (next = nextToPrepare())) return true;
      return std::any_of(active_.begin(), active_.end(),
                         [](const auto& a) { return a->finishable(); });
    });
    if (stopping_) return;
    if (std::shared_ptr<ActiveJob> done = takeFinishable()) {
      const std::string id = done->id;
      finishing_.insert(id);  // from here on a cancel is refused (JobManager::cancel)
      lock.unlock();
      finishGuarded(*done);
      done.reset();
      // glibc keeps freed heap in its arenas; a job's peak would otherwise stay resident
      // for the daemon's life.
      malloc_trim(0);
      lock.lock();
      finishing_.erase(id);
      continue;
    }
    if (!next) continue;
    const std::string id = to_prepare_[*next];
    to_prepare_.erase(to_prepare_.begin() + long(*next));
    lock.unlock();
    countRun(id);
    lock.lock();
    JobRecord record = jobs_[id];
    lock.unlock();
    auto prepared = prepareGuarded(record);
    if (!prepared) {
      failJob(id, prepared.error(), prepared.status().code());
      lock.lock();
      continue;
    }
    lock.lock();
    std::shared_ptr<ActiveJob> job = *prepared;
    JobRecord& live = jobs_[id];
    job->cancelled = live.cancel_requested;
    job->cancel_flag = live.cancel_requested;
    live.rdms_done = int(std::count(job->units_left.begin(), job->units_left.end(), 0));
    live.state = JobState::kRunning;
    if (live.started == 0.0) live.started = nowSeconds();
    saveRecord(id);
    active_.push_back(job);
    work_cv_.notify_all();
    exec_cv_.notify_all();
  }
}

bool JobManager::pickUnit(std::shared_ptr<ActiveJob>& job, size_t& unit) {
  std::shared_ptr<ActiveJob> best;
  for (const auto& a : active_) {
    if (!a->vulkan && a->hasPending() && (!best || jobPriority(*a) < jobPriority(*best))) best = a;
  }
  if (!best) return false;
  best->in_flight++;
  job = best;
  if (best->previewPending()) {
    unit = kPreviewUnit | best->preview->cursor++;
    return true;
  }
  while (best->unit_state[best->cursor] != 0) ++best->cursor;
  unit = best->cursor++;
  while (best->cursor < best->units.size() && best->unit_state[best->cursor] != 0) ++best->cursor;
  best->unit_state[unit] = 1;
  return true;
}

void JobManager::workerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    std::shared_ptr<ActiveJob> job;
    size_t unit = 0;
    work_cv_.wait(lock, [&] { return stopping_ || pickUnit(job, unit); });
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
  if (job.failure.ok()) job.failure = std::move(failure);
  job.cancelled = true, job.cancel_flag = true;
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
  std::lock_guard<std::mutex> lock(mutex_);
  job.in_flight--;
  if (job.finishable()) exec_cv_.notify_all();
}

Expected<Image> PublishedPass::ownImage(const RdmKey& key) const {
  if (!spill) {
    auto it = own.find(key);
    if (it == own.end()) return Status::notFound("RDM not in the published pass");
    return it->second;
  }
  auto it = spill_index.find(key);
  if (it == spill_index.end()) return Status::notFound("RDM not in the published pass");
  Image image;
  const Status read = spill->visit(it->second, [&](const RdmData& d) { image = d.image; });
  if (!read) return read;
  return image;
}

void JobManager::publish(const ActiveJob& job, int pass, const BakeSettings& settings,
                         std::map<RdmKey, Image> own, std::shared_ptr<const RdmSpill> spill) {
  auto p = std::make_shared<PublishedPass>();
  p->pass = pass, p->passes = job.passes(), p->settings = settings;
  p->view = job.view;
  p->own = std::move(own);
  if (spill) {
    const std::vector<RdmId> ids = spill->ids();
    for (size_t i = 0; i < ids.size(); ++i) p->spill_index[rdmKey(ids[i])] = i;
    p->spill = std::move(spill);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  published_[job.id] = std::move(p);
  JobRecord& record = jobs_[job.id];
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
    auto it = jobs_.find(id);
    return it == jobs_.end() || stopping_ || terminal(it->second.state) ||
           it->second.passes_done >= passes;
  };
  progress_cv_.wait_until(lock, deadline, done);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  return it->second;
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
  if (bookUnit(job, index, result, saved)) {
    lock.unlock();
    job.releaseFinished(size_t(u.rdm));
    lock.lock();
  }
  job.in_flight--;
  if (job.finishable()) exec_cv_.notify_all();
}

bool JobManager::bookUnit(ActiveJob& job, size_t index, const UnitResult& result,
                          const Status& saved) {
  const BakeUnit& u = job.units[index];
  if (saved.code() == StatusCode::kNoSpace && job.failure.ok()) {
    job.failure = saved;  // other write errors only cost a re-run after a restart
    job.cancelled = true, job.cancel_flag = true;
  }
  RdmRecord& rec = job.records[size_t(u.rdm)];
  rec.full_set.unite(result.full_set);
  rec.first_set.unite(result.first_set);
  rec.smooth = rec.smooth || result.smooth;
  job.unit_state[index] = 2;
  JobRecord& record = jobs_[job.id];
  record.units_done++;
  record.texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  record.rays += result.rays;
  record.bake_seconds += result.seconds;
  if (--job.units_left[size_t(u.rdm)] != 0) return false;
  record.rdms_done++;
  return true;
}

void JobManager::finishJob(ActiveJob& job) {
  JobRecord record;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    record = jobs_[job.id];
  }
  // A job that ends without results gives its spill file's disk back before it is seen to
  // end (a client told of a full disk may retry at once).
  if (!job.failure.ok() || job.cancelled) job.spill.reset();
  if (!job.failure.ok()) return failJob(job.id, job.failure.message(), job.failure.code());
  if (job.cancelled) {
    store_.removeUnits(job.id);
    std::lock_guard<std::mutex> lock(mutex_);
    JobRecord& live = jobs_[job.id];
    endJob(live, JobState::kCancelled);
    saveRecord(job.id);
    published_.erase(job.id);
    progress_cv_.notify_all();
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  publish(job, job.passes() - 1, job.settings, {}, job.spill);
  if (Status s = finalize(job, record); !s) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      published_.erase(job.id);  // the last holder of the spill besides the job
    }
    job.spill.reset();
    return failJob(job.id, s.message(), s.code());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& live = jobs_[job.id];
  endJob(live, JobState::kSucceeded);
  live.rdms_held_peak = job.storage->peakRdmsHeld();
  live.finalize_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  saveRecord(job.id);
  published_.erase(job.id);  // the job's files answer from now on
  progress_cv_.notify_all();
  store_.removeUnits(job.id);
}

}  // namespace rdm
