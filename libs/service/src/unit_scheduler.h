// The prepared jobs and the order their work units run in: CPU workers take one unit of the
// job that sorts first (jobPriority), the Vulkan worker whole RDMs of it per call; a finished
// unit is booked into its job and record; a job whose units all landed is handed to the
// executor to finish. Not thread-safe: JobManager calls it under its mutex, which also
// guards the `mutex-guarded` fields of ActiveJob.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "active_job.h"
#include "rdm/base/status.h"
#include "rdm/service/job.h"

namespace rdm {

// One call's work for the Vulkan worker: the whole preview pass, or final-pass units of
// whole RDMs (those still pending).
struct VulkanWork {
  std::shared_ptr<ActiveJob> job;
  bool preview = false;
  std::vector<size_t> units;
};

class UnitScheduler {
 public:
  void add(std::shared_ptr<ActiveJob> job) { active_.push_back(std::move(job)); }
  const std::vector<std::shared_ptr<ActiveJob>>& jobs() const { return active_; }
  bool empty() const { return active_.empty(); }

  // A CPU job's next unit (preview units carry kPreviewUnit), counted in flight; false when
  // no CPU job has one.
  bool pickUnit(std::shared_ptr<ActiveJob>& job, size_t& unit);
  // The highest-priority Vulkan job's next call, counted in flight: its whole preview pass,
  // or the pending units of its next RDMs in plan order, whole RDMs up to `call_paths` paths
  // (texels x spp) beyond the first.
  bool pickVulkanWork(VulkanWork& work, uint64_t call_paths);
  // Books a finished final-pass unit into its job (slot sets, unit state, a kNoSpace save
  // failure) and `record` (progress); true when it was its RDM's last, which the caller then
  // releases (ActiveJob::releaseFinished) outside the lock before the job leaves flight.
  static bool bookUnit(ActiveJob& job, size_t unit, const UnitResult& result, const Status& saved,
                       JobRecord& record);
  // A unit (or Vulkan call) that threw: the job keeps its first failure, stops taking units
  // and leaves flight. True when it is now finishable.
  static bool failInFlight(ActiveJob& job, Status failure);

  // Removes and returns a job whose units all landed (or that was cancelled and has none in
  // flight); null when none.
  std::shared_ptr<ActiveJob> takeFinishable();
  bool anyFinishable() const;
  void cancel(const std::string& id);  // the job takes no more units
  uint64_t pendingUnits() const;       // final-pass units not yet handed out

 private:
  std::vector<std::shared_ptr<ActiveJob>> active_;
};

}  // namespace rdm
