#include "rdm/base/failpoint.h"

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <new>

namespace rdm {
namespace {

std::atomic<Failpoint> g_armed{Failpoint::kNone};

}  // namespace

Status armFailpointFromEnvironment() {
  const char* env = std::getenv("RDM_FAILPOINT");
  const std::string name = env ? env : "";
  if (name.empty()) return armFailpoint(Failpoint::kNone), Status();
  if (name == "prepare_alloc") return armFailpoint(Failpoint::kPrepareAlloc), Status();
  if (name == "prepare_abort") return armFailpoint(Failpoint::kPrepareAbort), Status();
  if (name == "unit_alloc") return armFailpoint(Failpoint::kUnitAlloc), Status();
  if (name == "prepare_slow") return armFailpoint(Failpoint::kPrepareSlow), Status();
  return Status::invalid("RDM_FAILPOINT",
                         "RDM_FAILPOINT: unknown failpoint '" + name +
                             "' (prepare_alloc, prepare_abort, unit_alloc, prepare_slow)");
}

void armFailpoint(Failpoint point) {
  g_armed.store(point, std::memory_order_relaxed);
}

bool takeFailpoint(Failpoint point) {
  if (g_armed.load(std::memory_order_relaxed) != point || point == Failpoint::kNone) return false;
  Failpoint expected = point;
  return g_armed.compare_exchange_strong(expected, Failpoint::kNone);  // else fired elsewhere
}

void hitFailpoint(Failpoint point) {
  if (!takeFailpoint(point)) return;
  if (point == Failpoint::kPrepareAbort) std::raise(SIGKILL);  // as the kernel's OOM killer does
  throw std::bad_alloc();
}

}  // namespace rdm
