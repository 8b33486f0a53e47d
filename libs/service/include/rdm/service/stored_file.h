// Stored data that proves itself (docs/spec.md section 8.10, "Checksums"): a job's result
// files are listed with their XXH3 64 in `out/checksums.json`, written (fsync'd) when the job
// finishes, and checked whenever the daemon reads or serves one of them. A file that fails
// its check is renamed aside to `<name>.corrupt`, logged as event "corrupt" with its path and
// both hashes, and answered as kCorrupt from then on; it is never served or built upon.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "rdm/base/status.h"

namespace rdm {

constexpr const char* kChecksumsFile = "checksums.json";  // in a job's out/ directory
constexpr const char* kCorruptSuffix = ".corrupt";

// Writes `dir`/checksums.json: {"format": 1, "files": {"<name>": "<16 hex XXH3 64>"},
// "check": "<16 hex>"} over every regular file of `dir` but itself, temporary files,
// quarantined ones and rdms.store (whose records carry their own checksums). `check` is
// the XXH3 64 of the "files" object's compact dump, so a damaged manifest is told apart from
// the files it lists.
Status writeResultChecksums(const std::string& dir);

// The manifest of `dir`: kNotFound when there is none (a job finished before manifests
// existed: its files are served unverified), kCorrupt when it is torn or fails its check.
Expected<std::map<std::string, uint64_t>> readResultChecksums(const std::string& dir);

struct VerifiedFile {
  std::string bytes;
  uint64_t hash = 0;      // XXH3 64 of `bytes`
  bool verified = false;  // false: no manifest named the file (served as read)
};

// `dir`/`name` read whole and checked against the manifest. kCorrupt (the file quarantined
// and logged) when the bytes differ from the manifest's hash, when the manifest lists a file
// that is gone, or when the file was quarantined before; kNotFound when neither the manifest
// nor the directory has it.
Expected<VerifiedFile> readVerifiedResult(const std::string& dir, const std::string& name);

// The one reaction to a failed check: renames `path` to `path` + ".corrupt" (a failure to
// rename is logged too) and logs {"event": "corrupt", "path", "expected", "actual"} at error
// level; hashes are 16 hex digits, `actual` may say what else is wrong ("cut short").
void reportCorrupt(const std::string& path, const std::string& expected, const std::string& actual,
                   bool quarantine_file = true);

// XXH3 64 as the 16 lower-case hex digits the manifests and ETags use.
std::string hashHex(uint64_t hash);
std::optional<uint64_t> parseHashHex(const std::string& text);

}  // namespace rdm
