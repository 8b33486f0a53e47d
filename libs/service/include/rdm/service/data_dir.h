// The data directory belongs to one daemon at a time, and what a killed daemon left half
// written is swept before anything reads it (docs/api.md, "Persistence").
#pragma once

#include <cstddef>
#include <string>

#include "rdm/base/status.h"

namespace rdm {

// Creates `dir` if needed and takes an exclusive flock on DIR/.lock for as long as the
// returned descriptor is open; the kernel drops it when the process dies, SIGKILL included.
// A second daemon on the same directory is refused, naming it.
Expected<int> lockDataDir(const std::string& dir);

// Removes every regular file under `dir` whose name holds ".tmp" (the temporary half of an
// atomic write, rdm/file_util.h, that a kill interrupted), logging each; returns how many.
// Only safe while holding the directory's lock.
size_t sweepTempFiles(const std::string& dir);

}  // namespace rdm
