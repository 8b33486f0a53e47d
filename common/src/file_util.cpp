#include "rdm/file_util.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rdm {

Expected<std::string> readFileToString(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) return Status::error(path + ": read error");
  return os.str();
}

namespace {

// ENOSPC and EDQUOT are "no space"; every other errno is an IO failure.
Status writeError(const std::string& path, const char* what, int err) {
  const StatusCode code = err == ENOSPC || err == EDQUOT ? StatusCode::kNoSpace : StatusCode::kIo;
  return Status::error(code, path + ": " + what + ": " + std::strerror(err));
}

// Best effort: makes the rename itself durable where the filesystem syncs directories.
void syncParentDirectory(const std::string& path) {
  std::string dir = std::filesystem::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

namespace {

// A temp name of its own per write, beside `path` (so the rename stays in one directory):
// two writers of the same path never share one. Every name holds ".tmp", which the daemon's
// start-up sweep removes (rdm/data_dir.h).
std::string tempPathFor(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  return path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
}

}  // namespace

Status writeFileAtomic(const std::string& path, const std::string& contents,
                       Durability durability) {
  return writeFileAtomicStreamed(
      path, [&contents](const FileSink& sink) { sink(contents); }, durability);
}

Status writeFileAtomicStreamed(const std::string& path,
                               const std::function<void(const FileSink&)>& produce,
                               Durability durability) {
  const std::string tmp = tempPathFor(path);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return writeError(path, "cannot create", errno);
  int failed = 0;  // the errno of the first failed write
  produce([fd, &failed](std::string_view piece) {
    size_t written = 0;
    while (failed == 0 && written < piece.size()) {
      const ssize_t n = ::write(fd, piece.data() + written, piece.size() - written);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) failed = n == 0 ? ENOSPC : errno;
      if (n > 0) written += size_t(n);
    }
  });
  if (failed != 0) {
    ::close(fd);
    ::unlink(tmp.c_str());
    return writeError(path, "write failed", failed);
  }
  if (durability == Durability::kFsync && ::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    return writeError(path, "flush failed", err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    return writeError(path, "flush failed", err);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    return writeError(path, "rename failed", err);
  }
  if (durability == Durability::kFsync) syncParentDirectory(path);
  return {};
}

void quarantine(const std::string& path, const std::string& reason) {
  const std::string aside = path + ".quarantined-" + std::to_string(long(std::time(nullptr)));
  std::error_code ec;
  std::filesystem::rename(path, aside, ec);
  std::fprintf(stderr, "rdm: %s: %s; %s\n", path.c_str(), reason.c_str(),
               ec ? ("could not move it aside: " + ec.message()).c_str()
                  : ("moved aside to " + aside).c_str());
}

Status makeDirectories(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) return Status::error(path + ": cannot create directory: " + ec.message());
  return {};
}

}  // namespace rdm
