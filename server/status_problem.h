// Status -> RFC 9457 problem: the daemon maps a core Status by its code and field, never by
// its text. Loader messages without a field keep the loader's wording as the detail.
#pragma once

#include "problem.h"
#include "rdm/base/status.h"

namespace rdm::server {

// kBusy is the job limit (429 too-many-jobs). Failures of the server itself (kIo, kDevice,
// kInternal, kCancelled) are logged and answer a 500 that leaks nothing; kNoSpace, a failed
// write of the daemon's state, answers 507.
Problem problemOf(const Status& status);

}  // namespace rdm::server
