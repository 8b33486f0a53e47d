// Status -> RFC 9457 problem: the daemon maps a core Status by its code and field, never by
// its text. Loader messages without a field keep the loader's wording as the detail.
#pragma once

#include "problem.h"
#include "rdm/status.h"

namespace rdm::server {

Problem problemOf(const Status& status);
// A failed write of the daemon's state: logged; 507 problem+json when the disk is full, else
// a 500 that leaks nothing.
Problem storageProblem(const Status& status);

}  // namespace rdm::server
