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
  return Status::invalid("RDM_FAILPOINT", "RDM_FAILPOINT: unknown failpoint '" + name +
                                              "' (prepare_alloc, prepare_abort, unit_alloc)");
}

void armFailpoint(Failpoint point) {
  g_armed.store(point, std::memory_order_relaxed);
}

void hitFailpoint(Failpoint point) {
  if (g_armed.load(std::memory_order_relaxed) != point || point == Failpoint::kNone) return;
  Failpoint expected = point;
  if (!g_armed.compare_exchange_strong(expected, Failpoint::kNone)) return;  // fired elsewhere
  if (point == Failpoint::kPrepareAbort) std::raise(SIGKILL);  // as the kernel's OOM killer does
  throw std::bad_alloc();
}

}  // namespace rdm
