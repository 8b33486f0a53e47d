// The job queue and the bake executor (docs/spec.md section 8).
//
// Jobs are admitted by submit(), persisted, then prepared by one executor thread (scene ->
// world -> RDM plan, finished units restored from disk) and split into the core's work
// units. A pool of `threads` workers runs units of all prepared jobs, always picking the
// highest-priority job: incremental modes before full bakes, then fewer units, then older.
// Cancellation takes effect between units. When a job's last unit lands, the executor
// assembles and writes its atlas. Thread-safe.
#pragma once

#include <condition_variable>
#include <deque>
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
#include "rdm/service/job_store.h"
#include "rdm/service/metrics.h"
#include "rdm/service/scene_store.h"
#include "rdm/vulkan/vulkan_bake.h"

namespace rdm {

struct ActiveJob;

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
  // does. On Vulkan, naive-estimator jobs bake on `device` in one Vulkan worker beside the
  // CPU workers; other jobs bake on the CPU, or are refused at submit under an explicit
  // kVulkan.
  BakeBackend backend = BakeBackend::kCpu;
  std::string device;
  // Paths (texels x spp) one Vulkan call may take, whole RDMs, at least one: larger keeps a
  // GPU busier, smaller lets an incremental job overtake a full bake and a cancel land sooner.
  uint64_t vulkan_call_paths = uint64_t(1) << 22;
};

struct SubmitRequest {
  std::string scene_id;
  long long version = 0;  // 0: latest
  BakeSettings settings;
  BakeMode mode = BakeMode::kFull;
  std::string base_job;                                // empty: newest compatible
  RadianceFormat radiance = RadianceFormat::kFloat32;  // of the job's atlas.exr
  int face_light_spp = 0;                              // 0: no face_light.bin
  uint64_t memory_estimate = 0;                        // bytes, rdm/bake_estimate.h
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
  // Joins the threads; unfinished jobs this process worked on get their run back (a clean
  // stop is not a death).
  void stop();

  Expected<JobRecord> submit(const SubmitRequest& request);
  std::optional<JobRecord> get(const std::string& id) const;
  std::vector<JobRecord> list() const;  // newest first
  // Scene versions jobs still need: those of unfinished jobs and of the newest succeeded job
  // that can be a base (SceneStore::prune keeps them).
  std::set<long long> versionsInUse(const std::string& scene_id) const;
  Expected<JobRecord> cancel(const std::string& id);
  JobGauges gauges() const;
  // After start(): "cpu" or "vulkan on DEVICE", and why (the auto choice).
  std::string backendLine() const;
  // The latest pass a running job has published (null when none, or once its files exist).
  std::shared_ptr<const PublishedPass> published(const std::string& id) const;
  // Blocks until the job has published `passes` passes, ended, or `timeout_s` passed.
  std::optional<JobRecord> waitFor(const std::string& id, int passes, double timeout_s) const;
  const JobStore& store() const { return store_; }

 private:
  Status startBackend();
  Status assignBackend(JobRecord& job) const;
  Status chooseBase(const SubmitRequest& request, JobRecord& job) const;
  // Writes the job's face_light.bin when it asked for one (job_face_light.cpp).
  Status writeJobFaceLight(const ActiveJob& job, const JobRecord& record);
  Status bakeJobFaceLight(const ActiveJob& job, const JobRecord& record);  // may throw
  // Each thread's loop runs its jobs' work inside a catch of std::exception: a throwing
  // piece of work fails its job, never the process.
  void executorLoop();
  void workerLoop();
  // Outside mutex_: counts this process's run of the job on disk before work on it starts.
  void countRun(const std::string& id);
  // A prepare or finish that throws fails its job with the reason (jobFailure).
  Expected<std::shared_ptr<ActiveJob>> prepareGuarded(const JobRecord& job);
  void finishGuarded(ActiveJob& job);
  // A unit (or Vulkan call) that threw: the job stops taking units and fails once the
  // units in flight land.
  void failInFlight(ActiveJob& job, Status failure);
  // The restart's quarantine: true when the job met two deaths and was failed instead.
  bool quarantine(JobRecord& job);
  bool pickUnit(std::shared_ptr<ActiveJob>& job, size_t& unit);
  void runUnit(ActiveJob& job, size_t unit);
  void runPreviewUnit(ActiveJob& job, size_t unit);
  // Under mutex_: books a finished unit (its slot sets, the job's progress); true when it
  // was its RDM's last, which the caller then releases (ActiveJob::releaseFinished) before
  // the job leaves flight.
  bool bookUnit(ActiveJob& job, size_t unit, const UnitResult& result, const Status& saved);
  // The Vulkan worker (job_backend.cpp): whole RDMs per call, then per-unit booking.
  struct VulkanWork;
  void vulkanWorkerLoop();
  bool pickVulkanWork(VulkanWork& work);
  void runVulkanWork(VulkanWork& work);
  void runVulkanPreview(ActiveJob& job);
  void publish(const ActiveJob& job, int pass, const BakeSettings& settings,
               std::map<RdmKey, Image> own, std::shared_ptr<const RdmSpill> spill = nullptr);
  std::shared_ptr<ActiveJob> takeFinishable();
  // Under mutex_: the queued job to prepare next (incremental before full, then in order)
  // whose memory estimate fits beside the running jobs' (JobManagerOptions::memory_budget).
  std::optional<size_t> nextToPrepare();
  // job_runner.cpp: outside the lock.
  // A conflict (the job needs what this server lacks) is the client's to act on; any other
  // failure is the server's.
  Expected<std::shared_ptr<ActiveJob>> prepare(const JobRecord& job);
  Status finalize(ActiveJob& job, JobRecord& record);
  void finishJob(ActiveJob& job);
  void failJob(const std::string& id, const std::string& message,
               StatusCode code = StatusCode::kInternal);
  void saveRecord(const std::string& id);
  // Under mutex_: adds a job to jobs_ and the indexes below; ends one (state, finished time,
  // the unfinished set and the metric).
  JobRecord& addJob(JobRecord job);
  void endJob(JobRecord& job, JobState state);

  const JobManagerOptions options_;
  SceneStore& scenes_;
  JobStore& store_;
  Metrics& metrics_;
  mutable std::mutex mutex_;
  std::condition_variable work_cv_, exec_cv_;
  mutable std::condition_variable progress_cv_;  // a pass was published or a job ended
  std::map<std::string, std::shared_ptr<const PublishedPass>> published_;
  std::map<std::string, JobRecord> jobs_;  // never erased, so pointers into it stay valid
  // Per scene, its jobs in seq order; and the ids of jobs not yet terminal. They keep submit,
  // the base choice and retention's versionsInUse from walking every job ever kept.
  std::map<std::string, std::vector<const JobRecord*>> scene_jobs_;
  std::set<std::string> unfinished_;
  std::deque<std::string> to_prepare_;
  std::vector<std::shared_ptr<ActiveJob>> active_;
  bool stopping_ = false;
  long long next_seq_ = 1;
  std::set<std::string> finishing_;  // jobs in finishJob (mutex_)
  std::set<std::string> runs_here_;  // jobs whose runs_started counts this process (mutex_)
  std::thread executor_;
  std::vector<std::thread> workers_;
  std::string backend_line_;
  std::unique_ptr<VulkanBaker> vulkan_;  // set by start() when jobs may bake on Vulkan
  std::thread vulkan_worker_;
};

}  // namespace rdm
