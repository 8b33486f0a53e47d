// The job service in process (docs/spec.md section 8), no HTTP server: JobRecords alone
// (admission, queue order, the restart's quarantine) and JobManager on a temp data dir with
// the built-in chess scene at tiny settings (submit, priority, cancel, resume, a failure
// injected inside a unit, no head-of-line blocking behind another job's face light or
// preparation). Waits are bounded by kJobTimeout, far above a job's seconds.
#include <gtest/gtest.h>

#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "rdm/atlas/rdm_store.h"
#include "rdm/bake/face_light.h"
#include "rdm/base/failpoint.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/service/job_manager.h"
#include "rdm/service/job_records.h"
#include "test_requirements.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

constexpr double kJobTimeout = 120.0;  // seconds; a tiny chess job takes well under one
// A face light of chess at these samples per face bakes for minutes on 2 threads: longer
// than any test, so only a cancel or a stop ends it.
constexpr int kEndlessFaceLightSpp = 1 << 22;
// How long an interactive job may take beside another job's long phase, and how soon a
// cancel of a job in a long phase must end it (seconds; generous for a loaded 2-core machine,
// where the daemon's lowered-priority threads wait behind compilers, and ten times that under
// the sanitizers).
constexpr double kSlowdown = test::kSanitized ? 10.0 : 1.0;
constexpr double kInteractiveBound = 10.0 * kSlowdown;
constexpr double kCancelBound = 5.0 * kSlowdown;

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A data directory with one scene (the built-in chess at tiny settings), and the stores a
// JobManager works on. Fresh per test.
class JobService : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir() + "/job_service_" + std::to_string(getpid()) + "_" +
           testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    openStores();
    Scene chess = *builtinScene("chess");
    chess.bake.spp = 1, chess.bake.max_hemisphere = 4, chess.bake.max_bounces = 1;
    chess.face_light_spp = 0;
    settings_ = chess.bake;
    auto info = scenes_->create(std::move(chess));
    ASSERT_TRUE(info.ok()) << info.error();
    scene_id_ = info->id;
  }
  void TearDown() override {
    manager_.reset();
    armFailpoint(Failpoint::kNone);
    fs::remove_all(dir_);
  }

  // New stores on the same directory, as a restarted daemon opens them.
  void openStores() {
    manager_.reset();
    scenes_ = std::make_unique<SceneStore>(dir_, 8);
    ASSERT_TRUE(scenes_->load().ok());
    store_ = std::make_unique<JobStore>(dir_);
    metrics_ = std::make_unique<Metrics>();
  }

  void startManager(JobManagerOptions options = defaultOptions()) {
    manager_ = std::make_unique<JobManager>(options, *scenes_, *store_, *metrics_);
    const Status started = manager_->start();
    ASSERT_TRUE(started.ok()) << started.message();
  }

  static JobManagerOptions defaultOptions() {
    JobManagerOptions options;
    options.threads = 2;
    return options;
  }

  SubmitRequest request(BakeMode mode = BakeMode::kFull) const {
    SubmitRequest r;
    r.scene_id = scene_id_;
    r.settings = settings_;
    r.mode = mode;
    return r;
  }

  std::string submit(const SubmitRequest& r) {
    auto job = manager_->submit(r);
    EXPECT_TRUE(job.ok()) << job.error();
    return job.ok() ? job->id : std::string();
  }

  // The job once it ended (or as it is after kJobTimeout).
  JobRecord waitEnded(const std::string& id) {
    auto job = manager_->waitFor(id, 1 << 20, kJobTimeout);
    EXPECT_TRUE(job.has_value());
    EXPECT_TRUE(job && terminal(job->state)) << id << " did not end in " << kJobTimeout << " s";
    return job.value_or(JobRecord{});
  }

  // Polls (1 ms steps, at most kJobTimeout) until `done` holds for the job's record.
  template <class Pred>
  JobRecord waitUntil(const std::string& id, Pred done) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(kJobTimeout);
    std::optional<JobRecord> job = manager_->get(id);
    while (job && !done(*job) && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      job = manager_->get(id);
    }
    EXPECT_TRUE(job && done(*job)) << id << ": condition not met in " << kJobTimeout << " s";
    return job.value_or(JobRecord{});
  }

  void expectSucceeded(const JobRecord& job) {
    EXPECT_EQ(job.state, JobState::kSucceeded) << job.id << ": " << job.error;
    EXPECT_GT(job.units_total, 0u);
    EXPECT_EQ(job.units_done, job.units_total);
    EXPECT_EQ(job.rdms_done, job.rdms_rebake);
    EXPECT_TRUE(fs::exists(store_->outDir(job.id) + "/index.json"));
    EXPECT_TRUE(fs::exists(store_->outDir(job.id) + "/" + kRdmStoreFile));
    EXPECT_EQ(manager_->published(job.id), nullptr);  // its files answer now
  }

  // Scene version 2: one chess piece removed, so an exact job on it has work to do.
  void editScene() {
    auto patched =
        scenes_->patch(scene_id_,
                       nlohmann::json::parse(
                           R"({"base_version": 1, "edits": [{"at": [0, 1, 0], "block": null}]})"),
                       [](const Scene&) { return Status(); });
    ASSERT_TRUE(patched.ok()) << patched.error();
  }

  // Submits an exact job on the edited scene and waits for it; the seconds it took.
  double runExactJob(const std::string& base) {
    const auto start = std::chrono::steady_clock::now();
    const JobRecord exact = waitEnded(submit(request(BakeMode::kExact)));
    const double seconds = secondsSince(start);
    expectSucceeded(exact);
    EXPECT_EQ(exact.base_job, base);
    std::printf("exact job: %.3f s from submit to success\n", seconds);
    return seconds;
  }

  // Cancels a job in a long phase; it ends cancelled within kCancelBound, without results.
  void expectPromptCancel(const std::string& id) {
    const auto start = std::chrono::steady_clock::now();
    auto cancelled = manager_->cancel(id);
    ASSERT_TRUE(cancelled.ok()) << cancelled.error();
    const JobRecord ended = waitEnded(id);
    const double seconds = secondsSince(start);
    EXPECT_EQ(ended.state, JobState::kCancelled) << ended.error;
    EXPECT_LT(seconds, kCancelBound);
    std::printf("cancel: %.3f s from DELETE to cancelled\n", seconds);
    EXPECT_FALSE(fs::exists(store_->outDir(id) + "/index.json"));
    EXPECT_FALSE(fs::exists(store_->outDir(id) + "/" + kFaceLightFile));
  }

  std::string dir_, scene_id_;
  BakeSettings settings_;
  std::unique_ptr<SceneStore> scenes_;
  std::unique_ptr<JobStore> store_;
  std::unique_ptr<Metrics> metrics_;
  std::unique_ptr<JobManager> manager_;
};

TEST_F(JobService, RecordsRefuseBadRequestsAndTheLimit) {
  JobRecords records(*scenes_, *store_, *metrics_);
  ASSERT_TRUE(store_->init().ok());
  SubmitRequest unknown = request();
  unknown.scene_id = "s_nope";
  EXPECT_EQ(records.draft(unknown).status().code(), StatusCode::kNotFound);
  SubmitRequest version = request();
  version.version = 2;  // the scene has version 1 only
  EXPECT_EQ(records.draft(version).status().code(), StatusCode::kInvalidInput);
  auto draft = records.draft(request(BakeMode::kFast));
  ASSERT_TRUE(draft.ok()) << draft.error();
  // An incremental job needs a succeeded base.
  EXPECT_EQ(records.admit(request(BakeMode::kFast), *draft, 4).status().code(),
            StatusCode::kConflict);
  auto first = records.admit(request(), *records.draft(request()), 1);
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_TRUE(fs::exists(store_->jobDir(first->id) + "/job.json"));  // on disk when admitted
  EXPECT_EQ(records.admit(request(), *records.draft(request()), 1).status().code(),
            StatusCode::kBusy);
  // A queued job's cancel ends it at once; a second cancel conflicts.
  auto cancelled = records.cancel(first->id, false);
  ASSERT_TRUE(cancelled.ok()) << cancelled.error();
  EXPECT_EQ(cancelled->state, JobState::kCancelled);
  EXPECT_EQ(records.queued(), 0u);
  EXPECT_EQ(records.cancel(first->id, false).status().code(), StatusCode::kConflict);
}

TEST_F(JobService, RecordsQueueIncrementalBeforeFullAndQuarantineOnRestore) {
  ASSERT_TRUE(store_->init().ok());
  JobRecord base;
  base.id = "j_base", base.seq = 1, base.scene_id = scene_id_, base.scene_version = 1;
  base.state = JobState::kSucceeded, base.settings = settings_;
  JobRecord died = base;  // two daemon deaths met it
  died.id = "j_died", died.seq = 2, died.state = JobState::kRunning, died.runs_started = 2;
  JobRecord resumed = died;
  resumed.id = "j_resumed", resumed.seq = 3, resumed.runs_started = 1;
  JobRecords records(*scenes_, *store_, *metrics_);
  records.restore({resumed, died, base});
  EXPECT_EQ(records.find("j_died")->state, JobState::kFailed);
  EXPECT_NE(records.find("j_died")->error.find("quarantined"), std::string::npos);
  EXPECT_EQ(records.find("j_resumed")->state, JobState::kQueued);
  ASSERT_EQ(records.queued(), 1u);

  auto full = records.admit(request(), *records.draft(request()), 8);
  ASSERT_TRUE(full.ok()) << full.error();
  auto fast = records.admit(request(BakeMode::kFast), *records.draft(request(BakeMode::kFast)), 8);
  ASSERT_TRUE(fast.ok()) << fast.error();
  EXPECT_EQ(fast->base_job, "j_base");
  // The fast job overtakes both full jobs queued before it; then the queue keeps its order.
  std::vector<std::string> order;
  while (auto next = records.nextToPrepare(0, true, 0)) order.push_back(records.takeQueued(*next));
  EXPECT_EQ(order, (std::vector<std::string>{fast->id, "j_resumed", full->id}));
}

TEST_F(JobService, RecordsHoldAJobBackOverTheMemoryBudget) {
  JobRecords records(*scenes_, *store_, *metrics_);
  SubmitRequest big = request();
  big.memory_estimate = 600;
  ASSERT_TRUE(records.admit(big, *records.draft(big), 8).ok());
  EXPECT_FALSE(records.nextToPrepare(500, false, 1000).has_value());  // 500 + 600 > 1000
  EXPECT_EQ(records.nextToPrepare(400, false, 1000), std::optional<size_t>(0));
  EXPECT_EQ(records.nextToPrepare(0, true, 100), std::optional<size_t>(0));  // alone it runs
}

TEST_F(JobService, SubmitRunsToSuccessWithResults) {
  startManager();
  const std::string id = submit(request());
  ASSERT_FALSE(id.empty());
  const JobRecord job = waitEnded(id);
  expectSucceeded(job);
  EXPECT_GT(job.rays, 0u);
  EXPECT_EQ(manager_->list().size(), 1u);
  const JobGauges gauges = manager_->gauges();
  EXPECT_EQ(gauges.jobs_by_state.at("succeeded"), 1);
  EXPECT_EQ(gauges.queue_depth, 0);
  EXPECT_EQ(manager_->versionsInUse(scene_id_), (std::set<long long>{1}));  // a possible base
}

TEST_F(JobService, InteractiveJobOvertakesQueuedFullJob) {
  // One job at a time (each estimates the whole budget), one worker.
  JobManagerOptions options = defaultOptions();
  options.threads = 1;
  options.memory_budget = 1;
  startManager(options);
  SubmitRequest full = request();
  full.memory_estimate = 1;
  const std::string base = submit(full);
  expectSucceeded(waitEnded(base));
  const std::string running = submit(full);
  waitUntil(running, [](const JobRecord& j) { return j.state != JobState::kQueued; });
  const std::string queued_full = submit(full);
  SubmitRequest fast = request(BakeMode::kFast);
  fast.memory_estimate = 1;
  const std::string interactive = submit(fast);
  const JobRecord overtaker = waitEnded(interactive);
  const JobRecord overtaken = waitEnded(queued_full);
  EXPECT_EQ(overtaker.state, JobState::kSucceeded) << overtaker.error;
  EXPECT_EQ(overtaken.state, JobState::kSucceeded) << overtaken.error;
  EXPECT_EQ(overtaker.base_job, base);
  // Unless the first full job had ended before the fast one was submitted (then nothing
  // waited to be overtaken), the fast job was prepared and finished first.
  if (manager_->get(running)->finished < overtaker.created) GTEST_SKIP() << "no queue formed";
  EXPECT_LE(overtaker.finished, overtaken.started);
}

TEST_F(JobService, CancelEndsQueuedAndRunningJobs) {
  JobManagerOptions options = defaultOptions();
  options.threads = 1;
  options.memory_budget = 1;  // the second job stays queued behind the first
  startManager(options);
  SubmitRequest full = request();
  full.memory_estimate = 1;
  const std::string first = submit(full);
  const std::string second = submit(full);
  auto cancelled = manager_->cancel(second);
  ASSERT_TRUE(cancelled.ok()) << cancelled.error();
  EXPECT_TRUE(cancelled->cancel_requested);
  auto running = manager_->cancel(first);
  ASSERT_TRUE(running.ok()) << running.error();
  for (const std::string& id : {first, second}) {
    const JobRecord job = waitEnded(id);
    EXPECT_EQ(job.state, JobState::kCancelled) << id;
    EXPECT_FALSE(fs::exists(store_->outDir(id) + "/index.json")) << id;
  }
  EXPECT_EQ(manager_->cancel(first).status().code(), StatusCode::kConflict);
  EXPECT_EQ(manager_->cancel("j_none").status().code(), StatusCode::kNotFound);
  // The service goes on.
  expectSucceeded(waitEnded(submit(request())));
}

TEST_F(JobService, ResumesAfterTheManagerIsRecreated) {
  JobManagerOptions options = defaultOptions();
  options.threads = 1;
  startManager(options);
  const std::string id = submit(request());
  const JobRecord partial =
      waitUntil(id, [](const JobRecord& j) { return j.units_done >= 1 || terminal(j.state); });
  ASSERT_FALSE(terminal(partial.state)) << partial.error;
  openStores();  // destroys the manager: a clean stop, so the run is given back
  startManager(options);
  const std::optional<JobRecord> reloaded = manager_->get(id);
  ASSERT_TRUE(reloaded.has_value());
  if (terminal(reloaded->state)) GTEST_SKIP() << "the job ended before the stop";
  const JobRecord job = waitEnded(id);
  expectSucceeded(job);
  EXPECT_GE(job.units_restored, 1u);
  EXPECT_EQ(job.runs_started, 1);  // the clean stop gave the first run back
  // Resuming gives the bits a bake straight through gives.
  const JobRecord straight = waitEnded(submit(request()));
  expectSucceeded(straight);
  auto resumed_store = readFileToString(store_->outDir(id) + "/" + kRdmStoreFile);
  auto straight_store = readFileToString(store_->outDir(straight.id) + "/" + kRdmStoreFile);
  ASSERT_TRUE(resumed_store.ok() && straight_store.ok());
  EXPECT_TRUE(*resumed_store == *straight_store);
}

TEST_F(JobService, FailureInsideAUnitFailsTheJobAndTheNextSucceeds) {
  startManager();
  armFailpoint(Failpoint::kUnitAlloc);  // std::bad_alloc in the next unit any job runs
  const JobRecord failed = waitEnded(submit(request()));
  EXPECT_EQ(failed.state, JobState::kFailed);
  EXPECT_NE(failed.error.find("out of memory while baking a work unit"), std::string::npos)
      << failed.error;
  EXPECT_FALSE(fs::exists(store_->outDir(failed.id) + "/index.json"));
  expectSucceeded(waitEnded(submit(request())));
  EXPECT_EQ(manager_->gauges().jobs_by_state.at("failed"), 1);
}

// An exact job submitted while another job's face light bakes runs beside it and succeeds
// long before the face light ends; a cancel then ends the face light's job promptly.
TEST_F(JobService, ExactJobRunsWhileAFaceLightBakes) {
  startManager();
  const std::string base = submit(request());
  expectSucceeded(waitEnded(base));
  SubmitRequest lit = request();
  lit.face_light_spp = kEndlessFaceLightSpp;
  const std::string baking = submit(lit);
  // Its one pass is published once its units all landed, just before its face light.
  const std::optional<JobRecord> published = manager_->waitFor(baking, 1, kJobTimeout);
  ASSERT_TRUE(published && published->passes_done == 1) << baking;
  ASSERT_FALSE(terminal(published->state)) << published->error;
  editScene();
  EXPECT_LT(runExactJob(base), kInteractiveBound);
  EXPECT_FALSE(terminal(manager_->get(baking)->state));  // still in its face light
  expectPromptCancel(baking);
  expectSucceeded(waitEnded(submit(request())));  // the service goes on
}

// Likewise behind a slow preparation (the prepare_slow failpoint: 20 s), which a cancel
// stops between its steps.
TEST_F(JobService, ExactJobRunsWhileAnotherJobPrepares) {
  startManager();
  const std::string base = submit(request());
  expectSucceeded(waitEnded(base));
  armFailpoint(Failpoint::kPrepareSlow);
  const std::string slow = submit(request());
  waitUntil(slow, [](const JobRecord& j) { return j.runs_started >= 1; });
  // Its preparation takes the failpoint right after building the world (milliseconds).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  editScene();
  EXPECT_LT(runExactJob(base), kInteractiveBound);
  EXPECT_EQ(manager_->get(slow)->state, JobState::kQueued);  // still being prepared
  expectPromptCancel(slow);
}

// A stop during a face light or a preparation returns promptly and leaves the job to resume;
// the resumed job's results are those of a run straight through.
TEST_F(JobService, StopDuringLongPhasesIsPromptAndResumes) {
  for (const bool face_light : {true, false}) {
    SCOPED_TRACE(face_light ? "face light" : "preparation");
    startManager();
    SubmitRequest r = request();
    r.face_light_spp = face_light ? kEndlessFaceLightSpp : 0;
    if (!face_light) armFailpoint(Failpoint::kPrepareSlow);
    const std::string id = submit(r);
    if (face_light) {
      ASSERT_TRUE(manager_->waitFor(id, 1, kJobTimeout).has_value());
    } else {
      waitUntil(id, [](const JobRecord& j) { return j.runs_started >= 1; });
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ASSERT_FALSE(terminal(manager_->get(id)->state));
    const auto start = std::chrono::steady_clock::now();
    manager_->stop();
    const double seconds = secondsSince(start);
    EXPECT_LT(seconds, kCancelBound);
    std::printf("stop: %.3f s\n", seconds);
    armFailpoint(Failpoint::kNone);
    openStores();
    startManager();
    ASSERT_FALSE(terminal(manager_->get(id)->state));
    if (face_light) {
      ASSERT_TRUE(manager_->cancel(id).ok());  // an endless face light; resumed in the server test
      EXPECT_EQ(waitEnded(id).state, JobState::kCancelled);
      continue;
    }
    const JobRecord resumed = waitEnded(id);
    expectSucceeded(resumed);
    EXPECT_EQ(resumed.runs_started, 1);  // the stop gave its run back
    const JobRecord straight = waitEnded(submit(request()));
    expectSucceeded(straight);
    auto a = readFileToString(store_->outDir(id) + "/" + kRdmStoreFile);
    auto b = readFileToString(store_->outDir(straight.id) + "/" + kRdmStoreFile);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_TRUE(*a == *b);
  }
}

}  // namespace
}  // namespace rdm
