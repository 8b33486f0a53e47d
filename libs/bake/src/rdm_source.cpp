#include "rdm/bake/rdm_source.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "rdm/base/hash.h"

namespace rdm {
namespace {

Status spillError(const std::string& dir, const char* what, int err) {
  const StatusCode code = err == ENOSPC || err == EDQUOT ? StatusCode::kNoSpace : StatusCode::kIo;
  return Status::error(code,
                       "the bake's spill file in " + dir + ": " + what + ": " + std::strerror(err));
}

// An unnamed file in `dir`: O_TMPFILE where the filesystem has it, else a name unlinked at once.
int openAnonymous(const std::string& dir) {
  int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0 || (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL)) return fd;
  std::string name = dir + "/.rdm-spill-XXXXXX";
  fd = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd >= 0) ::unlink(name.c_str());
  return fd;
}

size_t texelFloats(const RdmId& id) {
  return size_t(2 * id.size) * size_t(3 * id.size) * 7;  // RGBZ + stderr RGB
}

// pwrite or pread of all `bytes`, resuming after short transfers and EINTR; a transfer of 0
// bytes is ENOSPC for a write and EIO for a read (the spill file ends early).
template <class Transfer, class Pointer>
bool transferAll(Transfer transfer, int fd, Pointer data, size_t bytes, uint64_t offset, int at_end,
                 int& err) {
  while (bytes > 0) {
    const ssize_t n = transfer(fd, data, bytes, off_t(offset));
    if (n <= 0) {
      err = n == 0 ? at_end : errno;
      if (err == EINTR) continue;
      return false;
    }
    data += n, bytes -= size_t(n), offset += uint64_t(n);
  }
  return true;
}

bool writeAll(int fd, const char* data, size_t bytes, uint64_t offset, int& err) {
  return transferAll(::pwrite, fd, data, bytes, offset, ENOSPC, err);
}

bool readAll(int fd, char* data, size_t bytes, uint64_t offset, int& err) {
  return transferAll(::pread, fd, data, bytes, offset, EIO, err);
}

// One spill record's checksum: the image's bytes, then its standard error's, hashed apart
// and combined so that no copy of the record is needed.
uint64_t recordHash(const RdmData& rdm) {
  const uint64_t image = contentHash(std::string_view(
      reinterpret_cast<const char*>(rdm.image.pixels.data()), rdm.image.pixels.size() * 4));
  const uint64_t error = contentHash(std::string_view(
      reinterpret_cast<const char*>(rdm.stderr_rgb.data()), rdm.stderr_rgb.size() * 4));
  return image ^ (error * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull);
}

}  // namespace

RdmDigest digestRdm(const RdmData& rdm) {
  RdmDigest d;
  d.id = rdm.id;
  d.skipped = rdm.skipped;
  const int s = rdm.id.size;
  for (int face = 0; face < 6; ++face) {
    float m = 0.0f;
    for (int y = s * (face / 2); y < s * (face / 2 + 1); ++y)
      for (int x = s * (face % 2); x < s * (face % 2 + 1); ++x)
        for (int c = 0; c < 3; ++c) m = std::max(m, std::fabs(rdm.image.at(x, y, c)));
    d.face_max[size_t(face)] = m;
  }
  for (float v : rdm.image.pixels) d.finite = d.finite && std::isfinite(v);
  return d;
}

std::vector<RdmId> MemoryRdmSource::ids() const {
  std::vector<RdmId> out;
  out.reserve(rdms_.size());
  for (const RdmData& d : rdms_) out.push_back(d.id);
  return out;
}

Expected<std::vector<RdmDigest>> MemoryRdmSource::digests() const {
  std::vector<RdmDigest> out;
  out.reserve(rdms_.size());
  for (const RdmData& d : rdms_) out.push_back(digestRdm(d));
  return out;
}

Status MemoryRdmSource::visit(size_t i, const std::function<void(const RdmData&)>& use) const {
  RDM_CHECK(i < rdms_.size());
  use(rdms_[i]);
  return {};
}

Expected<std::unique_ptr<RdmSpill>> RdmSpill::create(const std::string& dir) {
  const int fd = openAnonymous(dir);
  if (fd < 0) return spillError(dir, "cannot create", errno);
  return std::unique_ptr<RdmSpill>(new RdmSpill(fd, dir));
}

RdmSpill::~RdmSpill() {
  ::close(fd_);
}

void RdmSpill::append(const RdmData& rdm) {
  RDM_CHECK(rdm.image.pixels.size() == size_t(2 * rdm.id.size) * size_t(3 * rdm.id.size) * 4);
  RDM_CHECK(rdm.stderr_rgb.size() * 4 == rdm.image.pixels.size() * 3);
  Record record{digestRdm(rdm), 0, recordHash(rdm), rdm.max_samples};
  const size_t image_bytes = rdm.image.pixels.size() * sizeof(float);
  const size_t error_bytes = rdm.stderr_rgb.size() * sizeof(float);
  record.offset = end_.fetch_add(image_bytes + error_bytes);
  int err = 0;
  const bool written = writeAll(fd_, reinterpret_cast<const char*>(rdm.image.pixels.data()),
                                image_bytes, record.offset, err) &&
                       writeAll(fd_, reinterpret_cast<const char*>(rdm.stderr_rgb.data()),
                                error_bytes, record.offset + image_bytes, err);
  std::lock_guard lock(mutex_);
  if (!written && error_.ok()) error_ = spillError(dir_, "write", err);
  records_.push_back(std::move(record));
}

Status RdmSpill::status() const {
  std::lock_guard lock(mutex_);
  return error_;
}

std::vector<RdmId> RdmSpill::ids() const {
  std::lock_guard lock(mutex_);
  std::vector<RdmId> out;
  out.reserve(records_.size());
  for (const Record& r : records_) out.push_back(r.digest.id);
  return out;
}

Expected<std::vector<RdmDigest>> RdmSpill::digests() const {
  std::lock_guard lock(mutex_);
  std::vector<RdmDigest> out;
  out.reserve(records_.size());
  for (const Record& r : records_) out.push_back(r.digest);
  return out;
}

Status RdmSpill::visit(size_t i, const std::function<void(const RdmData&)>& use) const {
  Record record;
  {
    std::lock_guard lock(mutex_);
    RDM_CHECK(i < records_.size());
    record = records_[i];
  }
  RdmData rdm;
  rdm.id = record.digest.id;
  rdm.skipped = record.digest.skipped;
  rdm.max_samples = record.max_samples;
  rdm.image = Image(2 * rdm.id.size, 3 * rdm.id.size, 4);
  rdm.stderr_rgb.resize(texelFloats(rdm.id) / 7 * 3);
  const size_t image_bytes = rdm.image.pixels.size() * sizeof(float);
  int err = 0;
  if (!readAll(fd_, reinterpret_cast<char*>(rdm.image.pixels.data()), image_bytes, record.offset,
               err) ||
      !readAll(fd_, reinterpret_cast<char*>(rdm.stderr_rgb.data()),
               rdm.stderr_rgb.size() * sizeof(float), record.offset + image_bytes, err))
    return spillError(dir_, "read", err);
  if (recordHash(rdm) != record.hash) {
    const RdmId& id = rdm.id;
    return Status::error(StatusCode::kCorrupt,
                         "the bake's spill file in " + dir_ + ": the record of slot (" +
                             std::to_string(id.slot.x) + ", " + std::to_string(id.slot.y) + ", " +
                             std::to_string(id.slot.z) + ") level " + std::to_string(id.level) +
                             " fails its checksum (the disk returned other bytes)");
  }
  use(rdm);
  return {};
}

}  // namespace rdm
