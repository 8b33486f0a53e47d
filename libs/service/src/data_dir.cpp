#include "rdm/service/data_dir.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "rdm/base/log.h"

namespace rdm {

namespace fs = std::filesystem;

Expected<int> lockDataDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Status::error(StatusCode::kIo, "cannot create " + dir + ": " + ec.message());
  const std::string path = dir + "/.lock";
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return Status::error(StatusCode::kIo, "cannot open " + path);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    std::string holder(32, '\0');
    holder.resize(size_t(std::max<ssize_t>(0, ::pread(fd, holder.data(), holder.size(), 0))));
    while (!holder.empty() && holder.back() == '\n') holder.pop_back();
    ::close(fd);
    return Status::conflict("another rdm serve" + (holder.empty() ? "" : " (pid " + holder + ")") +
                            " uses the data directory " + dir + " (" + path + " is locked)");
  }
  // The holder's pid, for whoever finds the directory locked (best effort: the lock is what
  // counts).
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) == 0) (void)!::write(fd, pid.data(), pid.size());
  return fd;
}

size_t sweepTempFiles(const std::string& dir) {
  size_t removed = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.find(".tmp") == std::string::npos || !it->is_regular_file(ec)) continue;
    std::error_code rm;
    if (fs::remove(it->path(), rm)) {
      ++removed;
      logEvent(LogLevel::kWarn, "data_dir",
               {{"message", "removed " + it->path().string() + ", left by an interrupted write"}});
    }
  }
  return removed;
}

}  // namespace rdm
