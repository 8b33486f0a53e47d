// File helpers: whole-file reads and atomic writes (temp file in the same directory,
// fsync, rename), so a reader never sees a half-written file.
#pragma once

#include <string>

#include "rdm/status.h"

namespace rdm {

Expected<std::string> readFileToString(const std::string& path);
Status writeFileAtomic(const std::string& path, const std::string& contents);
Status makeDirectories(const std::string& path);

}  // namespace rdm
