// The job queue and the bake executor (docs/spec.md section 8).
//
// Jobs are admitted by submit(), persisted, then prepared (scene -> world -> RDM plan,
// finished units restored from disk) and split into the core's work units. A pool of
// `threads` workers runs units of all prepared jobs, always picking the highest-priority job:
// incremental modes before full bakes, then fewer units, then older. When a job's last unit
// lands, its atlas and face light are written. Preparing and finishing run each on a thread
// of its own, started by a dispatcher thread, so a long one (a large scene's world, a face
// light) holds up no other job: at most kMaxPreparing preparations of incremental jobs and as
// many of full jobs run at once, and the memory budget counts jobs in every phase.
// Cancellation takes effect between units, between a preparation's steps and between the
// face light's faces; a job is cancellable until its success is recorded. stop() ends every
// phase as promptly (docs/deploy.md, "Stopping"). Thread-safe.
//
// The pieces, each usable alone: JobRecords (job_records.h: admission, the records and the
// queue), UnitScheduler (src/unit_scheduler.h: which unit runs next, booking it) and
// JobFinisher (src/job_finisher.h: publishing passes, writing results). JobManager owns the
// lock they share and the threads that drive them.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/service/job.h"
#include "rdm/service/job_records.h"
#include "rdm/service/job_store.h"
#include "rdm/service/metrics.h"
#include "rdm/service/retention.h"
#include "rdm/service/scene_store.h"
#include "rdm/vulkan/vulkan_bake.h"

namespace rdm {

struct ActiveJob;
struct VulkanWork;
class JobFinisher;
class UnitScheduler;

// A pass's result as clients fetch it while the job runs (before its files exist).
struct PublishedPass {
  int pass = 0, passes = 1;
  BakeSettings settings;
  AtlasView view;  // the job's layout and every RDM's origin
  // Texels this job baked in this pass: a preview's in `own`, the final pass's in the job's
  // spill file, read one RDM at a time.
  std::map<RdmKey, Image> own;
  std::shared_ptr<const RdmSpill> spill;
  std::map<RdmKey, size_t> spill_index;
  Expected<Image> ownImage(const RdmKey& key) const;
};

struct JobManagerOptions {
  int threads = 0;    // bake worker threads; 0: all cores
  int max_jobs = 64;  // queued + running jobs; submit() refuses more with kBusy
  // Jobs run side by side while their memory estimates sum within this (rdm serve
  // --max-job-memory); a job that would pass it waits until others end. 0: no limit.
  uint64_t memory_budget = 0;
  // Where RDMs bake (docs/spec.md section 8.4). kAuto resolves at start() as `rdm bake`
  // does. On Vulkan, every job's RDMs bake on `device` in one Vulkan worker beside the CPU
  // workers; the face light bakes on the CPU.
  BakeBackend backend = BakeBackend::kCpu;
  std::string device;
  // Paths (texels x spp) one Vulkan call may take, whole RDMs, at least one: larger keeps a
  // GPU busier, smaller lets an incremental job overtake a full bake and a cancel land sooner.
  uint64_t vulkan_call_paths = uint64_t(1) << 22;
  // Which finished jobs expire (rdm serve --keep-jobs, --max-data-bytes, --fetch-grace); the
  // policy runs at start() and after each job ends.
  RetentionPolicy retention;
  // Where a Vulkan job encodes a bc6h atlas and denoises (rdm serve --result-passes): "auto"
  // on its device when that is a GPU (on lavapipe the CPU is faster at both), "vulkan" on its
  // device always, "cpu" on the CPU. The results are the same (docs/bc6h.md, docs/denoise.md).
  std::string result_passes = "auto";
};

class JobManager {
 public:
  JobManager(JobManagerOptions options, SceneStore& scenes, JobStore& store, Metrics& metrics);
  ~JobManager();
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  // Loads jobs, re-queues unfinished ones (failing those two daemon deaths met: quarantine,
  // JobRecord::runs_started), starts the threads.
  Status start();
  // Stops every phase (a unit in flight lands; a preparation or a face light stops between
  // steps or faces), joins the threads; unfinished jobs stay on disk to resume at the next
  // start and get their run back (a clean stop is not a death).
  void stop();

  Expected<JobRecord> submit(const SubmitRequest& request);
  std::optional<JobRecord> get(const std::string& id) const;
  std::vector<JobRecord> list() const;  // newest first
  // Scene versions jobs still need: those of unfinished jobs and of the newest succeeded job
  // that can be a base (SceneStore::prune keeps them).
  std::set<long long> versionsInUse(const std::string& scene_id) const;
  Expected<JobRecord> cancel(const std::string& id);
  // Deleting (docs/api.md, "Deleting and retention"). removeJob takes a finished job's
  // record and directory (renamed to trash first: a crash leaves it whole or gone): kNotFound;
  // kConflict while it is unfinished or writing its results, or while another kept job needs
  // it (JobRecords::dependents; the message names them); kIo when the rename fails. `why`
  // ("deleted", or "expired" for retention) is logged.
  Status removeJob(const std::string& id, const char* why = "deleted");
  // A scene and all its versions: kConflict while one of its jobs is unfinished, or while
  // finished ones are kept and `with_jobs` is false (named); with_jobs deletes those first.
  Status removeScene(const std::string& scene_id, bool with_jobs);
  // One version (SceneStore::removeVersion): kConflict while versionsInUse holds it.
  Status removeSceneVersion(const std::string& scene_id, long long version);
  // A client read the job's results now: retention spares it RetentionPolicy::fetch_grace_s.
  void noteFetched(const std::string& id);
  // One retention run (RetentionPolicy, chooseExpired): expires jobs until nothing more can
  // go; returns their ids. Also run by the retention thread after each job ends.
  std::vector<std::string> runRetention();
  JobGauges gauges() const;
  // After start(): "cpu" or "vulkan on DEVICE", and why (the auto choice).
  std::string backendLine() const;
  // The latest pass a running job has published (null when none, or once its files exist).
  std::shared_ptr<const PublishedPass> published(const std::string& id) const;
  // Blocks until the job has published `passes` passes, ended, or `timeout_s` passed.
  std::optional<JobRecord> waitFor(const std::string& id, int passes, double timeout_s) const;
  // For long polls parked without a thread (rdm serve): waits up to `block_s` for any pass or
  // job end (returns at the first), then tells for each (job id, passes) whether waitFor
  // would return now. One lock for all of them.
  std::vector<bool> waitsOver(const std::vector<std::pair<std::string, int>>& waits,
                              double block_s) const;
  const JobStore& store() const { return store_; }

 private:
  Status startBackend();
  Status assignBackend(JobRecord& job) const;
  // Each thread's loop runs its jobs' work inside a catch of std::exception: a throwing
  // piece of work fails its job, never the process. executorLoop dispatches preparations
  // and finishes to phase threads (runPhase) and joins those that ended.
  void executorLoop();
  void workerLoop();
  void vulkanWorkerLoop();
  void retentionLoop();  // runRetention at start and whenever a job ended
  // Whether the job's results were fetched within the retention policy's grace.
  bool fetchedRecently(const std::string& id) const;
  // removeJob's part under mutex_: the checks, the rename to trash and the record's erase.
  Status trashJobLocked(const std::string& id);
  // Under mutex_: the queued job to prepare next whose memory estimate fits beside those of
  // the jobs prepared, running and finishing (JobManagerOptions::memory_budget), while fewer
  // than kMaxPreparing jobs of its kind (incremental or full) are being prepared.
  std::optional<size_t> nextToPrepare();
  // Under `lock`: hand a job to a phase thread (runPhase).
  void startFinish(std::unique_lock<std::mutex>& lock, std::shared_ptr<ActiveJob> job);
  void startPrepare(std::unique_lock<std::mutex>& lock, size_t queued);
  // Runs `task` (which must not throw) on a new phase thread; inline, without the lock,
  // when no thread can be started.
  void runPhase(std::unique_lock<std::mutex>& lock, std::function<void()> task);
  void reapPhases(std::unique_lock<std::mutex>& lock);  // joins the phase threads that ended
  // The phase threads' tasks, outside the lock.
  void prepareTask(const std::shared_ptr<ActiveJob>& job, const JobRecord& record);
  void finishTask(std::shared_ptr<ActiveJob> job);
  // A prepare or finish that throws fails its job with the reason (jobFailure).
  Status prepareGuarded(const JobRecord& job, ActiveJob& into);
  void finishGuarded(ActiveJob& job);
  // A unit (or Vulkan call) that threw: the job stops taking units and fails once the
  // units in flight land.
  void failInFlight(ActiveJob& job, Status failure);
  void runUnit(ActiveJob& job, size_t unit);
  void runPreviewUnit(ActiveJob& job, size_t unit);
  // Takes the job out of flight (under mutex_) and wakes the executor when it can finish.
  void leaveFlight(ActiveJob& job);
  // The Vulkan worker (job_backend.cpp): whole RDMs per call, then per-unit booking.
  void runVulkanWork(VulkanWork& work);
  void runVulkanPreview(ActiveJob& job);
  void publish(const ActiveJob& job, int pass, const BakeSettings& settings,
               std::map<RdmKey, Image> own, std::shared_ptr<const RdmSpill> spill = nullptr);
  // job_runner.cpp: outside the lock.
  // A conflict (the job needs what this server lacks) is the client's to act on; any other
  // failure is the server's.
  // kCancelled when into.abort was set.
  Status prepare(const JobRecord& job, ActiveJob& into);
  void finishJob(ActiveJob& job);
  // Ends a job that ended without results (cancelled, or failed); outside the lock. A job
  // whose cancel was acknowledged ends cancelled even when its work failed after it.
  // `failure`: what failed after the cancel (logged).
  void cancelJob(const std::string& id, const std::string& failure = {});
  void failJob(const std::string& id, const std::string& message,
               StatusCode code = StatusCode::kInternal);
  // Structured log lines of a job's transitions (rdm/base/log.h, event "job"): started, a
  // pass published, and its end (state, seconds since it was created, the failure's reason).
  static void logJobStarted(const JobRecord& job);
  static void logJobPass(const JobRecord& job, int pass);
  void awaitFinishers(std::unique_lock<std::mutex>& lock, const std::vector<std::string>& ids);
  static void logJobEnd(const JobRecord& job, const std::string& reason = {});

  const JobManagerOptions options_;
  SceneStore& scenes_;
  JobStore& store_;
  Metrics& metrics_;
  mutable std::mutex mutex_;  // guards records_, scheduler_ and everything below but threads
  std::condition_variable work_cv_, exec_cv_;
  mutable std::condition_variable progress_cv_;  // a pass was published or a job ended
  JobRecords records_;
  std::unique_ptr<UnitScheduler> scheduler_;
  std::unique_ptr<JobFinisher> finisher_;
  std::map<std::string, std::shared_ptr<const PublishedPass>> published_;
  // Jobs on a phase thread, by id: their abort flags are set by cancel() and stop().
  std::map<std::string, std::shared_ptr<ActiveJob>> preparing_, finishing_;
  uint64_t finishes_done_ = 0;  // jobs that left finishing_: retention may count them now
  bool stopping_ = false;
  std::thread executor_;  // the dispatcher
  std::map<uint64_t, std::thread> phase_threads_;
  std::vector<uint64_t> phase_done_;  // phase threads whose task returned, to join
  uint64_t next_phase_ = 0;
  std::vector<std::thread> workers_;
  std::string backend_line_;
  std::unique_ptr<VulkanBaker> vulkan_;  // set by start() when jobs may bake on Vulkan
  std::thread vulkan_worker_;
  std::thread retention_;
  std::map<std::string, double> last_fetch_;  // job -> unix seconds of its last result fetch
};

}  // namespace rdm
