// File helpers: whole-file reads and atomic writes (temp file in the same directory,
// fsync, rename), so a reader never sees a half-written file.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "rdm/base/status.h"

namespace rdm {

Expected<std::string> readFileToString(const std::string& path);
// kFsync survives a power cut; kRenameOnly only a killed process (a torn file must then be
// detectable by its reader, e.g. by a checksum). Either way a reader sees the old file or the
// whole new one, a failed write leaves no temp file behind, and a full disk is kNoSpace.
enum class Durability { kFsync, kRenameOnly };
Status writeFileAtomic(const std::string& path, const std::string& contents,
                       Durability durability = Durability::kFsync);
// The same, for contents too large to hold twice: `produce` hands the file's bytes to the
// sink in consecutive pieces. After a failed write the sink drops what follows.
using FileSink = std::function<void(std::string_view)>;
Status writeFileAtomicStreamed(const std::string& path,
                               const std::function<void(const FileSink&)>& produce,
                               Durability durability = Durability::kFsync);
// A file written at any offsets under a temporary name beside `path`, renamed over `path`
// by commit(): for writers that seek back (an EXR's offset table) and for contents too large
// to hold in memory. Destroyed uncommitted, it leaves nothing behind.
class AtomicFileWriter {
 public:
  static Expected<std::unique_ptr<AtomicFileWriter>> create(const std::string& path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  // After a failed write, later writes are dropped and commit() fails with the first error.
  void writeAt(uint64_t offset, const char* data, size_t size);
  bool failed() const { return error_ != 0; }
  Status commit(Durability durability = Durability::kFsync);

 private:
  AtomicFileWriter(std::string path, std::string tmp, int fd)
      : path_(std::move(path)), tmp_(std::move(tmp)), fd_(fd) {}
  const std::string path_, tmp_;
  int fd_;
  int error_ = 0;  // errno of the first failed write
};
Status makeDirectories(const std::string& path);
// The one policy for unreadable state (docs/spec.md section 8.10): move `path` aside to
// `path.quarantined-<unix seconds>` and log why on stderr; never drop it silently and never
// refuse to start because of it.
void quarantine(const std::string& path, const std::string& reason);

}  // namespace rdm
