#include "rdm/base/build_id.h"

#include "rdm_git_commit.h"

namespace rdm {

std::string buildId() {
  return std::string("rdm-cpu ") + RDM_RELEASE + " (commit " + RDM_GIT_COMMIT + ") " + __VERSION__ +
         " " + __DATE__ + " " + __TIME__;
}

}  // namespace rdm
