#include "output_check.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace rdm::cli {
namespace {

namespace fs = std::filesystem;

Status probeWritable(const std::string& dir, const std::string& shown) {
  const std::string probe =
      (dir.empty() ? std::string(".") : dir) + "/.rdm-write-probe-" + std::to_string(::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Status::error(shown + ": cannot write there: " + std::strerror(errno));
  ::close(fd);
  ::unlink(probe.c_str());
  return {};
}

}  // namespace

Status prepareOutputDirectory(const std::string& dir, bool& created) {
  created = false;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    return Status::error(dir + ": exists and is not a directory");
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) return Status::error(dir + ": cannot create directory: " + ec.message());
    created = true;
  }
  return probeWritable(dir, dir);
}

Status checkOutputFile(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Status::error(path + ": is a directory, not a file");
  const std::string parent = fs::path(path).parent_path().string();
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    return Status::error(path + ": directory '" + parent + "' does not exist" +
                         (fs::exists(parent, ec) ? " (it is a file)" : ""));
  }
  return probeWritable(parent, path);
}

void removeIfEmpty(const std::string& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec) && fs::is_empty(dir, ec)) fs::remove(dir, ec);
}

std::string extensionOf(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace rdm::cli
