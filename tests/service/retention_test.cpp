// Retention and deletion without threads or HTTP: chooseExpired alone (count and byte
// limits, pins, the fetch grace), and JobRecords' dependents() / pinned() / erase() over a
// chain of incremental jobs whose rdms.bin name their RDMs' origin jobs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "rdm/bake/unit_checkpoint.h"
#include "rdm/service/job_records.h"
#include "rdm/service/retention.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

RetentionCandidate candidate(const std::string& id, long long seq, uint64_t bytes = 100) {
  RetentionCandidate c;
  c.id = id, c.seq = seq, c.bytes = bytes;
  return c;
}

TEST(Retention, KeepsTheNewestJobsOfTheCount) {
  RetentionPolicy policy;
  policy.keep_jobs = 2;
  // Given out of order: the oldest (lowest seq) go first.
  auto out =
      chooseExpired({candidate("c", 3), candidate("a", 1), candidate("d", 4), candidate("b", 2)}, 0,
                    policy, 1000.0);
  EXPECT_EQ(out, (std::vector<std::string>{"a", "b"}));
  policy.keep_jobs = 10;
  EXPECT_TRUE(chooseExpired({candidate("a", 1), candidate("b", 2)}, 0, policy, 1000.0).empty());
}

TEST(Retention, ByteBudgetExpiresOldestUntilUnder) {
  RetentionPolicy policy;
  policy.keep_jobs = 0;  // no count limit
  policy.max_data_bytes = 1000;
  std::vector<RetentionCandidate> jobs = {candidate("a", 1, 300), candidate("b", 2, 300),
                                          candidate("c", 3, 300), candidate("d", 4, 300)};
  // 1500 bytes: a and b must go (900 left), c stays.
  EXPECT_EQ(chooseExpired(jobs, 1500, policy, 0.0), (std::vector<std::string>{"a", "b"}));
  EXPECT_TRUE(chooseExpired(jobs, 1000, policy, 0.0).empty());  // at the limit: nothing
  policy.max_data_bytes = 0;
  EXPECT_TRUE(chooseExpired(jobs, 1 << 30, policy, 0.0).empty());  // 0: no limit
}

TEST(Retention, NeverExpiresPinnedOrRecentlyFetchedJobs) {
  RetentionPolicy policy;
  policy.keep_jobs = 1;
  policy.fetch_grace_s = 60;
  std::vector<RetentionCandidate> jobs = {candidate("a", 1), candidate("b", 2), candidate("c", 3),
                                          candidate("d", 4)};
  jobs[0].pinned = true;       // needed by a kept job
  jobs[1].last_fetch = 990.0;  // fetched 10 s ago
  jobs[2].last_fetch = 900.0;  // fetched 100 s ago: past the grace
  jobs[3].pinned = true;       // the scene's newest base
  EXPECT_EQ(chooseExpired(jobs, 0, policy, 1000.0), (std::vector<std::string>{"c"}));
  // Over the limit with every candidate kept: the limit is a target, nothing is forced.
  for (auto& j : jobs) j.pinned = true;
  EXPECT_TRUE(chooseExpired(jobs, 0, policy, 1000.0).empty());
}

// JobRecords over a data directory: a full job A, an exact job B on A whose result copies
// RDMs A baked, an exact job C on B that re-baked every RDM B copied from A.
class RetentionRecords : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir() + "/retention_" + std::to_string(getpid()) + "_" +
           testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    scenes_ = std::make_unique<SceneStore>(dir_, 8);
    ASSERT_TRUE(scenes_->load().ok());
    store_ = std::make_unique<JobStore>(dir_);
    ASSERT_TRUE(store_->init().ok());
    records_ = std::make_unique<JobRecords>(*scenes_, *store_, metrics_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  JobRecord job(const std::string& id, long long seq, BakeMode mode, const std::string& base,
                JobState state = JobState::kSucceeded) {
    JobRecord j;
    j.id = id, j.seq = seq, j.mode = mode, j.base_job = base, j.state = state;
    j.scene_id = "s0000000000000001", j.scene_version = 1;
    EXPECT_TRUE(store_->saveJob(j).ok());
    return j;
  }
  // rdms.bin of `id`: one RDM per origin.
  void origins(const std::string& id, const std::vector<std::string>& from) {
    std::vector<RdmRecord> records;
    for (size_t i = 0; i < from.size(); ++i) {
      RdmRecord r;
      r.id.slot = {int(i), 0, 0}, r.id.level = 7, r.id.size = 2;
      r.origin_job = from[i];
      records.push_back(r);
    }
    ASSERT_TRUE(store_->saveRdmRecords(id, records).ok());
  }

  std::string dir_;
  Metrics metrics_;
  std::unique_ptr<SceneStore> scenes_;
  std::unique_ptr<JobStore> store_;
  std::unique_ptr<JobRecords> records_;
};

TEST_F(RetentionRecords, DependentsFollowTheOriginsOfEachResult) {
  const std::string a = "j000000000000000a", b = "j000000000000000b", c = "j000000000000000c",
                    d = "j000000000000000d";
  std::vector<JobRecord> loaded = {job(a, 1, BakeMode::kFull, ""), job(b, 2, BakeMode::kExact, a),
                                   job(c, 3, BakeMode::kExact, b)};
  origins(a, {a, a});
  origins(b, {a, b});
  origins(c, {b, c});  // re-baked the RDM B had copied from A
  records_->restore(loaded);
  EXPECT_EQ(records_->dependents(a), (std::vector<std::string>{b}));
  EXPECT_EQ(records_->dependents(b), (std::vector<std::string>{c}));
  EXPECT_TRUE(records_->dependents(c).empty());
  // A and B are needed; C is the scene's newest job that can be a base.
  EXPECT_EQ(records_->pinned(), (std::set<std::string>{a, b, c}));

  // Deleting C frees B of its dependent, and B becomes the newest base.
  records_->erase(c);
  EXPECT_EQ(records_->find(c), nullptr);
  EXPECT_TRUE(records_->dependents(b).empty());
  EXPECT_EQ(records_->pinned(), (std::set<std::string>{a, b}));
  EXPECT_EQ(records_->sceneJobs("s0000000000000001"), (std::vector<std::string>{a, b}));
}

TEST_F(RetentionRecords, AnUnfinishedJobPinsItsBaseAndTheBasesOrigins) {
  const std::string a = "j000000000000000a", b = "j000000000000000b", q = "j000000000000000e",
                    f = "j000000000000000f";
  std::vector<JobRecord> loaded = {job(a, 1, BakeMode::kFull, ""), job(b, 2, BakeMode::kFast, a),
                                   job(f, 3, BakeMode::kFull, "", JobState::kFailed),
                                   job(q, 4, BakeMode::kExact, a, JobState::kQueued)};
  origins(a, {a});
  origins(b, {a, b});
  records_->restore(loaded);
  EXPECT_EQ(records_->dependents(a), (std::vector<std::string>{q, b}));  // newest first
  EXPECT_TRUE(records_->dependents(f).empty());                          // no results
  // A fast job is never a base: A stays the newest base; F (failed) and B are free... but B's
  // copies pin A, and nothing pins B.
  const std::set<std::string> pinned = records_->pinned();
  EXPECT_TRUE(pinned.count(a));
  EXPECT_FALSE(pinned.count(b));
  EXPECT_FALSE(pinned.count(f));
}

}  // namespace
}  // namespace rdm
