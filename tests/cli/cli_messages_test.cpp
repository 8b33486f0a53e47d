// What `rdm` says about bad input: numbers out of range in words, one exit code (2) for usage
// errors, scene files that are empty or directories, busy ports, outputs checked before any
// work; and inputs a new user gives that must just work (an atlas directory to preview, a
// server URL with a trailing slash).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>

#include "cli_run.h"
#include "rdm/base/file_util.h"
#include "server_process.h"

namespace rdm {
namespace {

const std::string kTiny = " --spp 1 --max-hemisphere 4 ";

// `r` is a usage error (exit 2) whose message contains `words` and no CLI11 range text.
void expectUsageError(const CliResult& r, const std::string& words) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, words)) << r.err;
  EXPECT_FALSE(contains(r.err, "not in range")) << r.err;
  EXPECT_FALSE(contains(r.err, "179769")) << r.err;
}

TEST(CliMessages, NumbersOutOfRangeAreRefusedInWords) {
  const std::string out = " -o " + tempDir("numbers");
  expectUsageError(runRdm("bake --scene chess --threads -1" + out),
                   "--threads: must be 0 (all cores) or a positive whole number, got '-1'");
  expectUsageError(runRdm("render --scene chess --threads -1" + out + ".exr"),
                   "--threads: must be 0 (all cores) or a positive whole number");
  expectUsageError(runRdm("bake --scene chess --threads two" + out),
                   "--threads: must be 0 (all cores) or a positive whole number, got 'two'");
  expectUsageError(runRdm("bake --scene chess --max-hemisphere 6" + out),
                   "--max-hemisphere: must be a power of two from 2 to 256, got '6'");
  expectUsageError(runRdm("bake --scene chess --face-light 70000" + out),
                   "--face-light: must be a whole number from 0 to 65536");
  expectUsageError(runRdm("bake --scene chess --target-error -0.1" + out),
                   "--target-error: must be 0 (off) or a positive number");
  expectUsageError(runRdm("bake --scene chess --backend vulkan --predict" + out),
                   "--predict times a pilot of a CPU bake; it is not supported on the Vulkan "
                   "backend; use --backend cpu");
  expectUsageError(runRdm("render --scene chess --width 0" + out + ".exr"),
                   "--width: must be a positive whole number, got '0'");
  expectUsageError(runRdm("preview a.exr --noise --noise-scale 0 -o a.png"),
                   "--noise-scale: must be a number above 0");
  expectUsageError(runRdm("serve --data-dir " + tempDir("numbers_data") + " --port 70000"),
                   "--port: must be a whole number from 0 to 65535, got '70000'");
  expectUsageError(runRdm("fetch j_0 --server http://127.0.0.1:1 --timeout 0" + out),
                   "--timeout: must be a positive number");
  // CLI11's own checks, wherever a verb still uses them, are worded the same way.
  expectUsageError(runRdm("submit chess --server http://127.0.0.1:1 --face-light -1"),
                   "--face-light: must be 0 or a positive whole number, got '-1'");
  EXPECT_FALSE(std::filesystem::exists(tempDir("numbers")));
}

TEST(CliMessages, UsageErrorsExitWith2InEveryVerb) {
  const std::string dir = tempDir("usage");
  expectUsageError(runRdm("bake --scene chess --spp 0 -o " + dir),
                   "--spp: must be a whole number from 1 to 65536, got '0'");
  expectUsageError(runRdm("render --scene chess --spp 0 -o " + dir + ".exr"),
                   "--spp: must be a positive whole number, got '0'");
  expectUsageError(runRdm("bake -o " + dir), "no scene given");
  expectUsageError(runRdm("render -o " + dir + ".exr"), "no scene given");
  expectUsageError(runRdm("bake chess.json --scene chess -o " + dir), "not both");
  EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(CliMessages, EmptySceneFileAndDirectoryAreNamedAsSuch) {
  const std::string dir = tempDir("scene_files");
  std::filesystem::create_directories(dir + "/folder");
  ASSERT_TRUE(writeFileAtomic(dir + "/empty.json", "").ok());
  for (const std::string verb : {"bake", "scene", "render"}) {
    const std::string out =
        verb == "scene" ? "" : " -o " + dir + "/out" + (verb[0] == 'r' ? ".exr" : "");
    CliResult empty = runRdm(verb + " " + dir + "/empty.json" + out);
    EXPECT_EQ(empty.code, 1) << verb;
    EXPECT_TRUE(contains(empty.err, dir + "/empty.json: scene file is empty")) << empty.err;
    CliResult folder = runRdm(verb + " " + dir + "/folder" + out);
    EXPECT_EQ(folder.code, 1) << verb;
    EXPECT_TRUE(contains(folder.err, dir + "/folder: is a directory, not a scene file"))
        << folder.err;
    EXPECT_FALSE(contains(empty.err + folder.err, "invalid JSON")) << empty.err << folder.err;
  }
}

TEST(CliMessages, PreviewTakesAnAtlasDirectory) {
  const std::string dir = tempDir("preview_dir");
  ASSERT_EQ(runRdm("bake --scene chess" + kTiny + "-q -o " + dir).code, 0);
  for (const std::string mode : {"", " --depth"}) {
    const std::string png = dir + "/view" + (mode.empty() ? "" : "_depth") + ".png";
    CliResult r = runRdm("preview " + dir + mode + " -o " + png);
    ASSERT_EQ(r.code, 0) << mode << ": " << r.err;
    auto bytes = readFileToString(png);
    ASSERT_TRUE(bytes.ok());
    EXPECT_EQ(bytes->substr(1, 3), "PNG");
  }
  const std::string empty = tempDir("preview_empty");
  std::filesystem::create_directories(empty);
  CliResult none = runRdm("preview " + empty + " -o " + empty + "/a.png");
  EXPECT_EQ(none.code, 1);
  EXPECT_TRUE(contains(none.err, empty + ": a directory without atlas.exr (")) << none.err;
  CliResult missing = runRdm("preview " + empty + "/nonexistent -o " + empty + "/a.png");
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(contains(missing.err, empty + "/nonexistent")) << missing.err;
  EXPECT_TRUE(contains(missing.err, "No such file or directory")) << missing.err;
}

TEST(CliMessages, AtlasInputsThatAreNotAtlasesSayWhy) {
  const std::string dir = tempDir("not_atlas");
  std::filesystem::create_directories(dir + "/empty");
  CliResult missing = runRdm("diff " + dir + "/none " + dir + "/empty");
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(contains(missing.err, dir + "/none: no such file or directory")) << missing.err;
  EXPECT_TRUE(contains(missing.err, "holds index.json and atlas.exr")) << missing.err;
  CliResult empty = runRdm("diff " + dir + "/empty " + dir + "/empty");
  EXPECT_EQ(empty.code, 1);
  EXPECT_TRUE(contains(empty.err, dir + "/empty: no index.json in it")) << empty.err;
}

TEST(CliMessages, ServerUrlMayEndInASlash) {
  const std::string dir = tempDir("slash");
  std::filesystem::create_directories(dir);
  test::ServerProcess server(dir + "/data", {"--threads", "1"});
  ASSERT_GT(server.port(), 0);
  CliResult submit = runRdm("submit furnace --server " + server.url() + "/");
  ASSERT_EQ(submit.code, 0) << submit.err;
  const size_t at = submit.out.find("job ");
  ASSERT_NE(at, std::string::npos) << submit.out;
  const std::string job = submit.out.substr(at + 4, submit.out.find('\n', at) - at - 4);
  CliResult status = runRdm("status " + job + " --server " + server.url() + "//");
  EXPECT_EQ(status.code, 0) << status.err;
  EXPECT_TRUE(contains(status.out, "job:       " + job)) << status.out;
  CliResult path = runRdm("status " + job + " --server " + server.url() + "/v1");
  EXPECT_EQ(path.code, 2);
  EXPECT_TRUE(contains(path.err, "without a path")) << path.err;
}

// A loopback TCP socket listening on a free port; closed on destruction.
class Listener {
 public:
  Listener() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof a;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), size) != 0 ||
        ::listen(fd_, 1) != 0 || ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &size) != 0)
      return;
    port_ = ntohs(a.sin_port);
  }
  ~Listener() {
    if (fd_ >= 0) ::close(fd_);
  }
  int port() const { return port_; }

 private:
  int fd_ = -1;
  int port_ = 0;
};

TEST(CliMessages, ServeOnABusyPortSaysItIsInUse) {
  Listener busy;
  ASSERT_GT(busy.port(), 0);
  const std::string port = std::to_string(busy.port());
  CliResult r = runRdm("serve --data-dir " + tempDir("busy_data") + " --bind 127.0.0.1 --port " +
                       port + " --log-level off");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(contains(r.err, "cannot listen on 127.0.0.1:" + port + ": Address already in use"))
      << r.err;
  EXPECT_TRUE(contains(r.err, "--port 0")) << r.err;
}

// Every verb that writes refuses an impossible output before reading its inputs: the
// message names the output, not the (missing) inputs.
TEST(CliMessages, OutputsAreCheckedBeforeAnyWork) {
  const std::string missing = tempDir("no_inputs");
  const struct {
    std::string args, output;
  } cases[] = {
      {"merge " + missing + "/s0 " + missing + "/s1 -o /dev/null/out", "/dev/null/out"},
      {"scene " + missing + "/x.json -o /dev/null/x.json", "/dev/null/x.json"},
      {"flip " + missing + "/a.exr " + missing + "/b.exr --map /dev/null/m.png", "/dev/null/m.png"},
      {"preview " + missing + "/a.exr -o /dev/null/a.png", "/dev/null/a.png"},
      {"import " + missing + "/m.vox -o /dev/null/s.json", "/dev/null/s.json"},
      {"fetch j_0 --server http://127.0.0.1:1 -o /dev/null/out", "/dev/null/out"},
  };
  for (const auto& c : cases) {
    CliResult r = runRdm(c.args);
    EXPECT_EQ(r.code, 1) << c.args;
    EXPECT_TRUE(contains(r.err, c.output)) << c.args << ": " << r.err;
    EXPECT_FALSE(contains(r.err, missing)) << c.args << ": " << r.err;
  }
}

}  // namespace
}  // namespace rdm
