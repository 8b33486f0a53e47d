#include "rdm/base/build_id.h"

namespace rdm {

std::string buildId() {
  return std::string("rdm-cpu ") + __VERSION__ + " " + __DATE__ + " " + __TIME__;
}

}  // namespace rdm
