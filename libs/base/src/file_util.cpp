#include "rdm/base/file_util.h"

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
#include <utility>

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
// start-up sweep removes (rdm/service/data_dir.h).
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
  auto file = AtomicFileWriter::create(path);
  if (!file) return file.status();
  uint64_t offset = 0;
  produce([&](std::string_view piece) {
    (*file)->writeAt(offset, piece.data(), piece.size());
    offset += piece.size();
  });
  return (*file)->commit(durability);
}

Expected<std::unique_ptr<AtomicFileWriter>> AtomicFileWriter::create(const std::string& path) {
  std::string tmp = tempPathFor(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return writeError(path, "cannot create", errno);
  return std::unique_ptr<AtomicFileWriter>(new AtomicFileWriter(path, std::move(tmp), fd));
}

AtomicFileWriter::~AtomicFileWriter() {
  if (fd_ < 0) return;
  ::close(fd_);
  ::unlink(tmp_.c_str());
}

void AtomicFileWriter::writeAt(uint64_t offset, const char* data, size_t size) {
  while (error_ == 0 && size > 0) {
    const ssize_t n = ::pwrite(fd_, data, size, off_t(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) error_ = n == 0 ? ENOSPC : errno;
    if (n > 0) data += n, size -= size_t(n), offset += uint64_t(n);
  }
}

Status AtomicFileWriter::commit(Durability durability) {
  RDM_CHECK(fd_ >= 0);
  const int fd = std::exchange(fd_, -1);
  Status failed;
  if (error_ != 0) failed = writeError(path_, "write failed", error_);
  if (failed.ok() && durability == Durability::kFsync && ::fsync(fd) != 0)
    failed = writeError(path_, "flush failed", errno);
  if (::close(fd) != 0 && failed.ok()) failed = writeError(path_, "flush failed", errno);
  if (failed.ok() && std::rename(tmp_.c_str(), path_.c_str()) != 0)
    failed = writeError(path_, "rename failed", errno);
  if (!failed.ok()) {
    ::unlink(tmp_.c_str());
    return failed;
  }
  if (durability == Durability::kFsync) syncParentDirectory(path_);
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
