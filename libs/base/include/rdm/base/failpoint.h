// Fault injection for the daemon's tests (docs/api.md, "Test hooks"): RDM_FAILPOINT=NAME,
// read once at daemon start, arms one failure that the code at a named point then raises.
// Unarmed (the normal case) a point costs one relaxed atomic load.
#pragma once

#include <string>

#include "rdm/base/status.h"

namespace rdm {

enum class Failpoint {
  kNone,
  kPrepareAlloc,  // "prepare_alloc": std::bad_alloc while a job is prepared
  kPrepareAbort,  // "prepare_abort": the process dies (SIGKILL) while a job is prepared
  kUnitAlloc,     // "unit_alloc": std::bad_alloc inside a work unit
  kPrepareSlow,   // "prepare_slow": a job's preparation takes 20 s more (stops on a cancel)
};

// Arms the failpoint named by the environment variable RDM_FAILPOINT (unset or empty: none).
// kInvalidInput naming the variable for an unknown name.
Status armFailpointFromEnvironment();
// Arms `point` directly (kNone disarms).
void armFailpoint(Failpoint point);
// When `point` is armed and has not fired in this process: fires it once (throws
// std::bad_alloc or kills the process). Otherwise does nothing.
void hitFailpoint(Failpoint point);
// True once when `point` is armed and has not fired: the caller acts it out (kPrepareSlow).
bool takeFailpoint(Failpoint point);

}  // namespace rdm
