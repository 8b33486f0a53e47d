#include "rdm/service/job_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "rdm/base/file_util.h"
#include "rdm/base/log.h"
#include "rdm/service/resource_id.h"

namespace rdm {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

}  // namespace

Status JobStore::init() {
  if (Status s = makeDirectories(dir_); !s) return s;
  emptyTrash();  // jobs a crash left half-deleted
  return {};
}

std::vector<JobRecord> JobStore::loadAll() const {
  std::vector<JobRecord> jobs;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string id = entry.path().filename().string();
    if (!validId(id, 'j')) continue;
    auto text = readFileToString(jobDir(id) + "/job.json");
    if (!text) {  // the directory exists only once job.json was written
      quarantine(jobDir(id), "job.json is missing or unreadable");
      continue;
    }
    JobRecord job;
    json j = json::parse(*text, nullptr, false);
    if (!j.is_discarded() && jobFromJson(j, job) && job.id == id) {
      jobs.push_back(std::move(job));
    } else {
      quarantine(jobDir(id), "job.json is empty, torn or not a job record");
    }
  }
  return jobs;
}

Status JobStore::saveJob(const JobRecord& job) const {
  if (Status s = makeDirectories(jobDir(job.id)); !s) return s;
  return writeFileAtomic(jobDir(job.id) + "/job.json", jobToJson(job).dump(1) + "\n");
}

Status JobStore::savePlan(const std::string& id, const std::vector<RdmId>& plan) const {
  json j = json::array();
  for (const RdmId& r : plan) j.push_back({r.slot.x, r.slot.y, r.slot.z, r.level, r.size});
  return writeFileAtomic(jobDir(id) + "/plan.json", j.dump() + "\n");
}

std::optional<std::vector<RdmId>> JobStore::loadPlan(const std::string& id) const {
  auto text = readFileToString(jobDir(id) + "/plan.json");
  if (!text) return std::nullopt;
  try {
    std::vector<RdmId> plan;
    for (const json& r : json::parse(*text)) {
      RdmId rid;
      rid.slot = {r.at(0).get<int>(), r.at(1).get<int>(), r.at(2).get<int>()};
      rid.level = r.at(3), rid.size = r.at(4);
      plan.push_back(rid);
    }
    return plan;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

Status JobStore::saveUnit(const std::string& id, const UnitResult& unit, int) const {
  const std::string path = jobDir(id) + "/" + kUnitLogFile;
  const std::string record = unitLogRecord(unit);
  std::lock_guard<std::mutex> lock(append_mutex_);
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0)
    return Status::error(StatusCode::kIo, path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  const off_t before = ::fstat(fd, &st) == 0 ? st.st_size : -1;
  size_t written = 0;
  int err = 0;
  while (written < record.size()) {
    const ssize_t n = ::write(fd, record.data() + written, record.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      err = n == 0 ? ENOSPC : errno;
      break;
    }
    written += size_t(n);
  }
  if (err != 0 && before >= 0 && ::ftruncate(fd, before) != 0) err = errno;  // no torn record
  ::close(fd);
  if (err == 0) return {};
  const StatusCode code = err == ENOSPC || err == EDQUOT ? StatusCode::kNoSpace : StatusCode::kIo;
  return Status::error(code, path + ": append failed: " + std::strerror(err));
}

size_t JobStore::forEachUnit(const std::string& id,
                             const std::function<void(UnitResult&)>& use) const {
  std::ifstream log(jobDir(id) + "/" + kUnitLogFile, std::ios::binary);
  return log ? forEachLoggedUnit(log, use) : 0;
}

size_t JobStore::countUnitFiles(const std::string& id) const {
  return forEachUnit(id, [](UnitResult&) {});
}

void JobStore::removeUnits(const std::string& id) const {
  std::error_code ec;
  fs::remove(jobDir(id) + "/" + kUnitLogFile, ec);
}

void JobStore::removeOutputs(const std::string& id) const {
  std::error_code ec;
  fs::remove_all(outDir(id), ec);
  fs::remove(jobDir(id) + "/rdms.bin", ec);
}

Status JobStore::saveRdmRecords(const std::string& id,
                                const std::vector<RdmRecord>& records) const {
  return writeFileAtomic(jobDir(id) + "/rdms.bin", encodeRdmRecords(records));
}

std::optional<std::vector<RdmRecord>> JobStore::loadRdmRecords(const std::string& id) const {
  auto bytes = readFileToString(jobDir(id) + "/rdms.bin");
  if (!bytes) return std::nullopt;
  return decodeRdmRecords(*bytes);
}

namespace {

constexpr const char* kTrashPrefix = ".trash-";

// Bytes of the regular files under `path` (a vanished entry counts 0: a job may be deleted
// meanwhile).
uint64_t treeBytes(const fs::path& path) {
  uint64_t bytes = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code size_ec;
    if (it->is_regular_file(size_ec)) {
      const uintmax_t n = it->file_size(size_ec);
      if (!size_ec) bytes += n;
    }
  }
  return bytes;
}

}  // namespace

Status JobStore::trashJob(const std::string& id) const {
  std::error_code ec;
  fs::rename(jobDir(id), dir_ + "/" + kTrashPrefix + id, ec);
  if (ec) return Status::error(StatusCode::kIo, jobDir(id) + ": cannot delete: " + ec.message());
  return {};
}

void JobStore::emptyTrash() const {
  std::error_code ec;
  std::vector<fs::path> trash;
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    if (entry.path().filename().string().rfind(kTrashPrefix, 0) == 0) trash.push_back(entry.path());
  }
  for (const fs::path& p : trash) {
    fs::remove_all(p, ec);
    if (ec) logEvent(LogLevel::kWarn, "data_dir", {{"message", p.string() + ": " + ec.message()}});
  }
}

void JobStore::removeTrashed(const std::string& id) const {
  std::error_code ec;
  fs::remove_all(dir_ + "/" + kTrashPrefix + id, ec);  // what stays is swept at the next init()
}

uint64_t JobStore::jobBytes(const std::string& id) const {
  return treeBytes(jobDir(id));
}

uint64_t JobStore::dataBytes() const {
  return treeBytes(fs::path(dir_).parent_path());
}

}  // namespace rdm
