#include "rdm/service/job_manager.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <new>
#include <thread>

#include "active_job.h"
#include "rdm/base/build_id.h"
#include "rdm/base/check.h"
#include "rdm/base/parallel.h"
#include "rdm/base/thread_priority.h"
#include "rdm/service/resource_id.h"

namespace rdm {
namespace {

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

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

bool JobManager::quarantine(JobRecord& job) {
  if (job.runs_started < 2) return false;
  const bool baking = store_.loadPlan(job.id).has_value();
  const std::string times =
      job.runs_started == 2 ? "twice" : std::to_string(job.runs_started) + " times";
  job.state = JobState::kFailed, job.finished = nowSeconds();
  job.error = "the daemon stopped " + times + " while this job was being " +
              (baking ? "baked" : "prepared") +
              "; quarantined, not resumed: it may need more memory than this server has (see "
              "the server log); submit it again with a smaller settings.max_hemisphere, "
              "\"radiance\": \"half\" or the scene in smaller parts";
  std::fprintf(stderr, "rdm serve: job %s: %s\n", job.id.c_str(), job.error.c_str());
  store_.removeUnits(job.id);
  store_.removeOutputs(job.id);
  if (Status s = store_.saveJob(job); !s)
    std::fprintf(stderr, "rdm serve: job %s: %s\n", job.id.c_str(), s.message().c_str());
  return true;
}

JobManager::JobManager(JobManagerOptions options, SceneStore& scenes, JobStore& store,
                       Metrics& metrics)
    : options_(options), scenes_(scenes), store_(store), metrics_(metrics) {}

JobManager::~JobManager() {
  stop();
}

Status JobManager::start() {
  if (Status s = startBackend(); !s) return s;
  if (Status s = store_.init(); !s) return s;
  std::vector<JobRecord> loaded = store_.loadAll();
  std::sort(loaded.begin(), loaded.end(),
            [](const JobRecord& a, const JobRecord& b) { return a.seq < b.seq; });
  for (JobRecord& job : loaded) {
    next_seq_ = std::max(next_seq_, job.seq + 1);
    if (!terminal(job.state)) {
      if (job.cancel_requested) {
        job.state = JobState::kCancelled, job.finished = nowSeconds();
        store_.removeUnits(job.id);
        // The record on disk keeps cancel_requested, so a failed save cancels it again at
        // the next start.
        if (Status s = store_.saveJob(job); !s)
          std::fprintf(stderr, "rdm serve: job %s: %s\n", job.id.c_str(), s.message().c_str());
      } else if (!quarantine(job)) {
        job.state = JobState::kQueued;  // resumes; finished units are restored on prepare
        to_prepare_.push_back(job.id);
      }
    }
    addJob(std::move(job));
  }
  const int threads = workerCount(options_.threads);
  executor_ = std::thread([this] {
    lowerThreadPriority();
    runGuarded("executor", [this] { executorLoop(); });
  });
  for (int t = 0; t < threads; ++t) {
    workers_.emplace_back([this] {
      lowerThreadPriority();
      runGuarded("bake worker", [this] { workerLoop(); });
    });
  }
  if (vulkan_) {
    vulkan_worker_ = std::thread([this] {
      lowerThreadPriority();
      runGuarded("Vulkan worker", [this] { vulkanWorkerLoop(); });
    });
  }
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
  for (const std::string& id : runs_here_) {
    JobRecord& job = jobs_.at(id);
    if (terminal(job.state)) continue;
    job.runs_started = std::max(0, job.runs_started - 1);
    saveRecord(id);
  }
  runs_here_.clear();
}

void JobManager::countRun(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& job = jobs_.at(id);
  job.runs_started++;
  runs_here_.insert(id);
  saveRecord(id);  // before the work: a death during it is counted at the next start
}

Status JobManager::chooseBase(const SubmitRequest& req, JobRecord& job) const {
  auto compatible = [&](const JobRecord& b, bool strict) {
    return b.scene_id == job.scene_id && b.state == JobState::kSucceeded &&
           b.mode != BakeMode::kFast &&
           (!strict || (b.settings == job.settings && b.build == job.build &&
                        b.backend == job.backend && b.device == job.device));
  };
  const bool strict = job.mode == BakeMode::kExact;
  if (!req.base_job.empty()) {
    auto it = jobs_.find(req.base_job);
    if (it == jobs_.end()) return Status::notFound("no job '" + req.base_job + "'", "base_job");
    const JobRecord& b = it->second;
    if (b.scene_id != job.scene_id)
      return Status::conflict("base_job belongs to another scene", "base_job");
    if (b.state != JobState::kSucceeded)
      return Status::conflict("base_job has not succeeded", "base_job");
    if (!scenes_.get(b.scene_id, b.scene_version)) {
      return Status::conflict("base_job's scene version " + std::to_string(b.scene_version) +
                                  " is no longer kept (docs/spec.md section 8.3); use a newer base",
                              "base_job");
    }
    if (strict && !compatible(b, true)) {
      return Status::conflict(
          "mode exact needs a full or exact base job with the same settings, build, backend and "
          "device",
          "base_job");
    }
    job.base_job = b.id;
    return {};
  }
  const JobRecord* best = nullptr;
  const auto found = scene_jobs_.find(job.scene_id);
  static const std::vector<const JobRecord*> kNoJobs;
  const auto& candidates = found == scene_jobs_.end() ? kNoJobs : found->second;
  for (bool s : {true, strict}) {  // prefer same settings; fast may fall back to any
    for (auto b = candidates.rbegin(); b != candidates.rend() && !best; ++b) {
      if (compatible(**b, s)) best = *b;  // newest first
    }
    if (best) break;
  }
  if (!best)
    return Status::conflict("no compatible base job for mode " + std::string(modeName(job.mode)) +
                                ": run a full bake first",
                            "base_job");
  job.base_job = best->id;
  return {};
}

Expected<JobRecord> JobManager::submit(const SubmitRequest& req) {
  auto info = scenes_.info(req.scene_id);
  if (!info) return Status::notFound("no scene '" + req.scene_id + "'");
  JobRecord job;
  job.scene_id = req.scene_id;
  job.scene_version = req.version ? req.version : info->version;
  if (job.scene_version < 1 || job.scene_version > info->version) {
    return Status::invalidField("version",
                                "the scene has versions 1.." + std::to_string(info->version));
  }
  job.settings = req.settings;
  job.mode = req.mode;
  job.radiance = req.radiance;
  job.face_light_spp = req.face_light_spp;
  job.memory_estimate = req.memory_estimate;
  job.build = buildId();
  if (Status s = assignBackend(job); !s) return s;
  job.created = nowSeconds();
  std::lock_guard<std::mutex> lock(mutex_);
  const int active = int(unfinished_.size());
  if (active >= options_.max_jobs) {
    return Status::error(StatusCode::kBusy,
                         "the server holds " + std::to_string(active) + " unfinished jobs (limit " +
                             std::to_string(options_.max_jobs) + "); retry later");
  }
  if (job.mode != BakeMode::kFull) {
    if (Status s = chooseBase(req, job); !s) return s;
  }
  job.id = newId('j');
  job.seq = next_seq_++;
  if (Status s = store_.saveJob(job); !s) {
    std::error_code ec;
    std::filesystem::remove_all(store_.jobDir(job.id), ec);  // no empty job directory is left
    return s;
  }
  addJob(job);
  to_prepare_.push_back(job.id);
  exec_cv_.notify_all();
  return job;
}

std::optional<JobRecord> JobManager::get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  return it->second;
}

std::vector<JobRecord> JobManager::list() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<JobRecord> out;
  for (const auto& [id, j] : jobs_) out.push_back(j);
  std::sort(out.begin(), out.end(),
            [](const JobRecord& a, const JobRecord& b) { return a.seq > b.seq; });
  return out;
}

Expected<JobRecord> JobManager::cancel(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return Status::notFound("no job '" + id + "'");
  JobRecord& job = it->second;
  if (terminal(job.state))
    return Status::conflict("job already " + std::string(stateName(job.state)));
  if (finishing_.count(id) && !job.cancel_requested) {
    return Status::conflict("job " + id +
                            " is writing its results and will succeed; it can no longer " +
                            "be cancelled");
  }
  // The cancel is on disk before it is acknowledged or acted on: a failed save changes
  // nothing, so no restart can resume a job whose cancel was answered.
  JobRecord cancelled = job;
  cancelled.cancel_requested = true;
  auto queued = std::find(to_prepare_.begin(), to_prepare_.end(), id);
  const bool never_prepared = queued != to_prepare_.end();
  if (never_prepared) cancelled.state = JobState::kCancelled, cancelled.finished = nowSeconds();
  if (Status s = store_.saveJob(cancelled); !s) return s;
  job = cancelled;
  if (never_prepared) {  // cancelled at once
    to_prepare_.erase(queued);
    endJob(job, JobState::kCancelled);
  }
  for (auto& a : active_) {
    if (a->id == id) a->cancelled = true, a->cancel_flag = true;
  }
  exec_cv_.notify_all();
  progress_cv_.notify_all();
  return job;
}

std::set<long long> JobManager::versionsInUse(const std::string& scene_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::set<long long> out;
  for (const std::string& id : unfinished_) {
    const JobRecord& j = jobs_.at(id);
    if (j.scene_id != scene_id) continue;
    out.insert(j.scene_version);
    auto base = jobs_.find(j.base_job);  // the base's scene is diffed when the job starts
    if (base != jobs_.end()) out.insert(base->second.scene_version);
  }
  const auto found = scene_jobs_.find(scene_id);
  if (found == scene_jobs_.end()) return out;
  for (auto j = found->second.rbegin(); j != found->second.rend(); ++j) {
    if ((*j)->state == JobState::kSucceeded && (*j)->mode != BakeMode::kFast) {
      out.insert((*j)->scene_version);  // the newest that can be a base
      break;
    }
  }
  return out;
}

JobGauges JobManager::gauges() const {
  std::lock_guard<std::mutex> lock(mutex_);
  JobGauges g;
  for (JobState s : {JobState::kQueued, JobState::kRunning, JobState::kSucceeded, JobState::kFailed,
                     JobState::kCancelled}) {
    g.jobs_by_state[stateName(s)] = 0;
  }
  for (const auto& [id, j] : jobs_) {
    ++g.jobs_by_state[stateName(j.state)];
    g.queue_depth += terminal(j.state) ? 0 : 1;
  }
  for (const auto& a : active_) {
    for (size_t u = a->cursor; u < a->units.size(); ++u)
      g.units_pending += a->unit_state[u] == 0 ? 1 : 0;
  }
  return g;
}

void JobManager::saveRecord(const std::string& id) {
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return;
  if (Status s = store_.saveJob(it->second); !s)
    std::fprintf(stderr, "rdm serve: %s\n", s.message().c_str());
}

void JobManager::failJob(const std::string& id, const std::string& message, StatusCode code) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (terminal(jobs_[id].state)) return;  // a finish that threw after the job had ended
  }
  std::fprintf(stderr, "rdm serve: job %s failed: %s\n", id.c_str(), message.c_str());
  // Partial results go first: on a full disk that frees the space the record needs.
  store_.removeUnits(id);
  store_.removeOutputs(id);
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& job = jobs_[id];
  if (code == StatusCode::kNoSpace) {
    job.error =
        "the server's data directory is full, so a result could not be written; free space "
        "and submit the job again";
  } else if (code == StatusCode::kConflict || code == StatusCode::kTooLarge) {
    // What the job needs and this server lacks (a device, memory): the client's to act on.
    job.error = message;
  } else {
    job.error = "the bake failed on the server; see the server log";
  }
  endJob(job, JobState::kFailed);
  saveRecord(id);
  published_.erase(id);
  progress_cv_.notify_all();
}

JobRecord& JobManager::addJob(JobRecord job) {
  const std::string id = job.id;
  JobRecord& added = jobs_[id] = std::move(job);
  scene_jobs_[added.scene_id].push_back(&added);  // callers add in seq order
  if (!terminal(added.state)) unfinished_.insert(id);
  return added;
}

void JobManager::endJob(JobRecord& job, JobState state) {
  RDM_CHECK(terminal(state));
  job.state = state, job.finished = nowSeconds();
  unfinished_.erase(job.id);
  metrics_.jobFinished(stateName(state));
}

}  // namespace rdm
