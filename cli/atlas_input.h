// Atlases given as input (rdm diff, rdm preview): a path that is not one is refused with its
// reason and what an atlas directory holds, before anything is read.
#pragma once

#include <string>

#include "rdm/base/status.h"

namespace rdm::cli {

// `dir` exists, is a directory and holds index.json.
[[nodiscard]] Status checkAtlasDirectory(const std::string& dir);

// The EXR that `in` names: `in` itself when it is not a directory, else the directory's first
// atlas page (atlas.exr), refused when missing.
Expected<std::string> exrFileFor(const std::string& in);

}  // namespace rdm::cli
