#include "unit_scheduler.h"

#include <algorithm>
#include <set>

namespace rdm {

bool UnitScheduler::pickUnit(std::shared_ptr<ActiveJob>& job, size_t& unit) {
  std::shared_ptr<ActiveJob> best;
  for (const auto& a : active_) {
    if (!a->vulkan && a->hasPending() && (!best || jobPriority(*a) < jobPriority(*best))) best = a;
  }
  if (!best) return false;
  best->in_flight++;
  job = best;
  if (best->previewPending()) {
    unit = kPreviewUnit | best->preview->cursor++;
    return true;
  }
  while (best->unit_state[best->cursor] != 0) ++best->cursor;
  unit = best->cursor++;
  while (best->cursor < best->units.size() && best->unit_state[best->cursor] != 0) ++best->cursor;
  best->unit_state[unit] = 1;
  return true;
}

bool UnitScheduler::pickVulkanWork(VulkanWork& work, uint64_t call_paths) {
  std::shared_ptr<ActiveJob> best;
  for (const auto& a : active_) {
    if (a->vulkan && a->hasPending() && (!best || jobPriority(*a) < jobPriority(*best))) best = a;
  }
  if (!best) return false;
  best->in_flight++;
  work.job = best;
  if (best->previewPending()) {
    work.preview = true;
    best->preview->cursor = best->preview->units.size();
    return true;
  }
  std::set<int> rdms;
  uint64_t paths = 0;
  const uint64_t spp = uint64_t(std::max(1, best->settings.spp));
  for (size_t i = best->cursor; i < best->units.size(); ++i) {
    if (best->unit_state[i] != 0) continue;
    const BakeUnit& u = best->units[size_t(i)];
    if (!rdms.count(u.rdm)) {
      const RdmId& id = best->plan[size_t(u.rdm)];
      const uint64_t rdm_paths = 6 * uint64_t(id.size) * uint64_t(id.size) * spp;
      if (!rdms.empty() && paths + rdm_paths > call_paths) continue;
      rdms.insert(u.rdm);
      paths += rdm_paths;
    }
    best->unit_state[i] = 1;
    work.units.push_back(i);
  }
  while (best->cursor < best->units.size() && best->unit_state[best->cursor] != 0) ++best->cursor;
  return true;
}

bool UnitScheduler::bookUnit(ActiveJob& job, size_t index, const UnitResult& result,
                             const Status& saved, JobRecord& record) {
  const BakeUnit& u = job.units[index];
  if (saved.code() == StatusCode::kNoSpace && job.failure.ok()) {
    job.failure = saved;  // other write errors only cost a re-run after a restart
    job.cancelled = true, job.cancel_flag = true;
  }
  RdmRecord& rec = job.records[size_t(u.rdm)];
  rec.full_set.unite(result.full_set);
  rec.first_set.unite(result.first_set);
  rec.smooth = rec.smooth || result.smooth;
  job.unit_state[index] = 2;
  record.units_done++;
  record.texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  record.rays += result.rays;
  record.bake_seconds += result.seconds;
  if (--job.units_left[size_t(u.rdm)] != 0) return false;
  record.rdms_done++;
  return true;
}

bool UnitScheduler::failInFlight(ActiveJob& job, Status failure) {
  if (job.failure.ok()) job.failure = std::move(failure);
  job.cancelled = true, job.cancel_flag = true;
  job.in_flight--;
  return job.finishable();
}

std::shared_ptr<ActiveJob> UnitScheduler::takeFinishable() {
  for (size_t i = 0; i < active_.size(); ++i) {
    if (active_[i]->finishable()) {
      std::shared_ptr<ActiveJob> job = active_[i];
      active_.erase(active_.begin() + long(i));
      return job;
    }
  }
  return nullptr;
}

bool UnitScheduler::anyFinishable() const {
  return std::any_of(active_.begin(), active_.end(), [](const auto& a) { return a->finishable(); });
}

void UnitScheduler::cancel(const std::string& id) {
  for (auto& a : active_) {
    if (a->id == id) a->cancelled = true, a->cancel_flag = true;
  }
}

uint64_t UnitScheduler::pendingUnits() const {
  uint64_t pending = 0;
  for (const auto& a : active_) {
    for (size_t u = a->cursor; u < a->units.size(); ++u) pending += a->unit_state[u] == 0 ? 1 : 0;
  }
  return pending;
}

}  // namespace rdm
