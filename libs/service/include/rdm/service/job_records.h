// The jobs a daemon knows and the queue of those waiting to be prepared (docs/spec.md
// section 8): admission (the job limit, the base job's choice, the record on disk before the
// job exists), the restart's recovery (resume, cancel, quarantine) and every change of a
// job's record. Not thread-safe: JobManager calls it under its mutex; a test may drive one
// alone, without threads.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "rdm/base/status.h"
#include "rdm/service/job.h"
#include "rdm/service/job_store.h"
#include "rdm/service/metrics.h"
#include "rdm/service/scene_store.h"

namespace rdm {

struct SubmitRequest {
  std::string scene_id;
  long long version = 0;  // 0: latest
  BakeSettings settings;
  BakeMode mode = BakeMode::kFull;
  std::string base_job;                                // empty: newest compatible
  RadianceFormat radiance = RadianceFormat::kFloat32;  // of the job's atlas.exr
  int face_light_spp = 0;                              // 0: no face_light.bin
  bool denoise = false;                                // the cross-block denoiser (denoise.h)
  uint64_t memory_estimate = 0;                        // bytes, rdm/bake_estimate.h
};

class JobRecords {
 public:
  JobRecords(SceneStore& scenes, JobStore& store, Metrics& metrics)
      : scenes_(scenes), store_(store), metrics_(metrics) {}
  JobRecords(const JobRecords&) = delete;
  JobRecords& operator=(const JobRecords&) = delete;

  // The jobs JobStore::loadAll found: unfinished ones are queued again, except those whose
  // cancel was on disk (cancelled now) and those two daemon deaths met (failed:
  // JobRecord::runs_started).
  void restore(std::vector<JobRecord> loaded);
  // The record a request asks for (scene, version, settings, created now), before the
  // backend is assigned and admit() runs: kNotFound for an unknown scene, kInvalidInput for
  // a version it lacks. Touches no record (SceneStore is thread-safe).
  Expected<JobRecord> draft(const SubmitRequest& request) const;
  // Admits `job` (a draft with its backend): kBusy when `max_jobs` jobs are unfinished, the
  // base choice's refusal for an incremental mode, the save's error. On success the job has
  // its id and seq, is on disk and queued.
  Expected<JobRecord> admit(const SubmitRequest& request, JobRecord job, int max_jobs);
  // Marks the job cancelled on disk before anything acts on it: a queued job ends at once,
  // a prepared one when its units in flight land. kConflict once it ended, or while it
  // writes its results (`finishing`) unless a cancel was already asked.
  Expected<JobRecord> cancel(const std::string& id, bool finishing);

  const JobRecord* find(const std::string& id) const;
  JobRecord& at(const std::string& id);  // RDM_CHECKs that the job exists
  std::vector<JobRecord> list() const;   // newest first
  std::set<long long> versionsInUse(const std::string& scene_id) const;
  void countStates(JobGauges& gauges) const;  // jobs_by_state, queue_depth

  // The queue. nextToPrepare: index of the queued job to prepare next (incremental before
  // full, then in order) whose memory estimate fits beside `held` bytes of running jobs
  // within `budget` (0: no limit; with nothing running any job fits).
  std::optional<size_t> nextToPrepare(uint64_t held, bool none_running, uint64_t budget);
  std::string takeQueued(size_t index);
  const std::string& queuedId(size_t index) const { return to_prepare_.at(index); }
  size_t queued() const { return to_prepare_.size(); }

  // Counts this process's run of the job on disk (before work on it starts: a death during
  // it is counted at the next start); giveBackRuns at a clean stop undoes it for the jobs
  // that did not end.
  void countRun(const std::string& id);
  void giveBackRuns();
  // Ends a job (state, finished time, the unfinished set and the metric); fail() also sets
  // the error clients see for `code` and saves the record.
  void end(JobRecord& job, JobState state);
  void fail(const std::string& id, const std::string& message, StatusCode code);
  void save(const std::string& id);  // logs a failed write: the record in memory stands

  // Deleting (JobManager::removeJob, retention). The kept jobs that need `id`'s files, newest
  // first: unfinished jobs whose base is `id` or copies RDMs `id` baked, and succeeded jobs
  // whose result copies RDMs `id` baked (their rdms.bin names it as an RDM's origin).
  std::vector<std::string> dependents(const std::string& id);
  // Every job that must not expire: those a kept job needs (as dependents() reads it) and
  // each scene's newest succeeded job that can be a base.
  std::set<std::string> pinned();
  // Forgets a finished job (its files are the caller's); RDM_CHECKs that it ended.
  void erase(const std::string& id);
  std::vector<std::string> sceneJobs(const std::string& scene_id) const;  // oldest first
  uint64_t ended() const { return ended_; }  // jobs that ended since construction

 private:
  // The 409 when no base job fits `job`, naming what keeps the newest full bake out.
  Status noBase(const JobRecord& job, const std::vector<const JobRecord*>& candidates) const;
  Status chooseBase(const SubmitRequest& request, JobRecord& job) const;
  bool quarantine(JobRecord& job);
  JobRecord& add(JobRecord job);
  // The other jobs whose RDMs the succeeded job `id`'s result copies (the origin jobs its
  // rdms.bin names; a full job has none), read once and cached. When rdms.bin is unreadable:
  // its base and the base's origins, to be safe.
  const std::set<std::string>& originsOf(const std::string& id);

  SceneStore& scenes_;
  JobStore& store_;
  Metrics& metrics_;
  // Erased only by erase() (a deleted finished job), which also drops its pointer below.
  std::map<std::string, JobRecord> jobs_;
  // Per scene, its jobs in seq order; and the ids of jobs not yet terminal. They keep submit,
  // the base choice and retention's versionsInUse from walking every job ever kept.
  std::map<std::string, std::vector<const JobRecord*>> scene_jobs_;
  std::set<std::string> unfinished_;
  std::deque<std::string> to_prepare_;
  std::set<std::string> runs_here_;  // jobs whose runs_started counts this process
  long long next_seq_ = 1;
  std::map<std::string, std::set<std::string>> origins_;  // originsOf's cache
  uint64_t ended_ = 0;
};

}  // namespace rdm
