// Output paths are checked before any work starts, so an unwritable or impossible `-o`
// fails at once instead of after a long bake.
#pragma once

#include <string>

#include "rdm/base/status.h"

namespace rdm::cli {

// Creates `dir` (and parents) when missing and proves it writable by creating and removing a
// probe file. `created` is set when this call created `dir`.
Status prepareOutputDirectory(const std::string& dir, bool& created);

// `path` names a file whose directory exists and is writable, and is not itself a directory.
Status checkOutputFile(const std::string& path);

// Removes `dir` when it is empty (undoing prepareOutputDirectory after a cancelled bake).
void removeIfEmpty(const std::string& dir);

// The lower-case extension of `path` without the dot ("" when none).
std::string extensionOf(const std::string& path);

}  // namespace rdm::cli
