// The build's identity, recorded in every job the daemon runs and printed by `--version` of
// `rdm` and `rdm-viewer`: the backend, the release, the source commit ("-dirty" when tracked
// files differed from it), the compiler and the time the core was built.
#pragma once

#include <string>

namespace rdm {

std::string buildId();

}  // namespace rdm
