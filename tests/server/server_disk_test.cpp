// The daemon on a full disk (docs/api.md, "Persistence and resume"): a real `rdm serve`
// whose data directory is a 1 MiB tmpfs. A bake that cannot write its results fails with a
// persisted state and a clear reason, leaves no temp, zero-byte or unit files, and is not
// re-run after a restart; uploads on a full disk get 507; once space is freed the daemon
// works again without a restart.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "server_process.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class SmallDisk {
 public:
  explicit SmallDisk(const std::string& dir) : dir_(dir) {
    fs::create_directories(dir);
    mounted_ = ::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=1m") == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  bool mounted() const { return mounted_; }

 private:
  std::string dir_;
  bool mounted_ = false;
};

int countFiles(const std::string& dir, const std::function<bool(const fs::path&)>& match) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file() && match(it->path())) ++n;
  }
  return n;
}

JobProgress waitEnded(BakeClient& c, const std::string& id) {
  auto j = c.jobProgress(id, 30.0);
  for (int i = 0; i < 10 && j.ok() && !j->terminal(); ++i) j = c.jobProgress(id, 30.0);
  EXPECT_TRUE(j.ok()) << (j.ok() ? "" : j.error());
  return j.ok() ? *j : JobProgress();
}

TEST(ServerDisk, FullDiskFailsTheJobCleanlyAndRecoversWithoutRestart) {
  const std::string dir = testing::TempDir() + "/server_disk_" + std::to_string(getpid());
  SmallDisk disk(dir);
  if (!disk.mounted())
    GTEST_SKIP() << "mounting a 1 MiB tmpfs needs root with CAP_SYS_ADMIN (CI runs as root)";
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 1, scene.bake.max_hemisphere = 16;  // results of several MiB
  scene.face_light_spp = 0;
  std::string job_id;
  {
    test::ServerProcess server(dir, {"--threads", "2"});
    ASSERT_GT(server.port(), 0);
    auto c = test::connectClient(server);
    auto up = c->uploadScene(sceneToJson(scene));
    ASSERT_TRUE(up.ok()) << up.error();
    auto job = c->submitBake((*up)["id"], json::object());
    ASSERT_TRUE(job.ok()) << job.error();
    job_id = (*job)["id"];
    const JobProgress done = waitEnded(*c, job_id);
    EXPECT_EQ(done.state, "failed");
    EXPECT_NE(done.error.find("full"), std::string::npos) << done.error;
    EXPECT_EQ(
        countFiles(dir,
                   [](const fs::path& p) { return p.string().find(".tmp") != std::string::npos; }),
        0);
    EXPECT_EQ(countFiles(dir, [](const fs::path& p) { return fs::file_size(p) == 0; }), 0);
    EXPECT_FALSE(fs::exists(dir + "/jobs/" + job_id + "/units.log"));

    // Fill what is left: an upload gets 507 and leaves no scene directory behind.
    {
      std::ofstream filler(dir + "/filler", std::ios::binary);
      const std::string block(64 * 1024, 'x');
      for (int i = 0; i < 64 && filler.write(block.data(), std::streamsize(block.size())); ++i) {
      }
    }
    const size_t scenes_before = std::distance(fs::directory_iterator(dir + "/scenes"), {});
    auto refused = c->post("/v1/scenes", sceneToJson(scene));
    ASSERT_TRUE(refused.ok()) << refused.error();
    EXPECT_EQ(refused->status, 507) << refused->body;
    EXPECT_EQ(refused->header("Content-Type"), "application/problem+json");
    EXPECT_EQ(size_t(std::distance(fs::directory_iterator(dir + "/scenes"), {})), scenes_before);
    // Space freed: the same daemon takes the upload.
    fs::remove(dir + "/filler");
    auto again = c->uploadScene(sceneToJson(scene));
    EXPECT_TRUE(again.ok()) << again.error();
  }
  // A restart neither loses nor repeats the failed job.
  test::ServerProcess server(dir, {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  auto c = test::connectClient(server);
  auto job = c->jobProgress(job_id);
  ASSERT_TRUE(job.ok()) << job.error();
  EXPECT_EQ(job->state, "failed");
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

// One daemon per data directory, and what a killed one left half written is swept at start.
TEST(ServerDisk, DataDirectoryIsLockedAndInterruptedWritesAreSwept) {
  const std::string dir = testing::TempDir() + "/server_lock_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir + "/jobs/j0000000000000001");
  const std::string torn = dir + "/jobs/j0000000000000001/job.json.tmp";
  std::ofstream(torn) << "{\"half\":";
  test::ServerProcess server(dir, {"--threads", "1"});
  ASSERT_GT(server.port(), 0);
  EXPECT_FALSE(fs::exists(torn));
  const std::string out = dir + "/second.txt";
  const std::string second =
      std::string(RDM_BINARY) + " serve --data-dir " + dir + " --port 0 > " + out + " 2>&1";
  EXPECT_NE(std::system(second.c_str()), 0);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("another rdm serve (pid "), std::string::npos) << text;
}

}  // namespace
}  // namespace rdm
