// Where a daemon job's RDMs bake (docs/spec.md section 8.4): the backend chosen at start, the
// one each job records at submit, and the Vulkan worker. The Vulkan worker bakes whole RDMs
// per call (the kernel's texels do not depend on the batch), then checkpoints and books each
// of their units as a CPU worker would, so resume, cancel and the slot sets work alike.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include "active_job.h"
#include "job_finisher.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/log.h"
#include "rdm/service/job_manager.h"
#include "unit_scheduler.h"

namespace rdm {

Status JobManager::startBackend() {
  const BackendChoice choice = resolveBakeBackend(options_.backend, options_.device);
  if (choice.backend == BakeBackend::kCpu) {
    backend_line_ = "cpu (" + choice.reason + ")";
    return {};
  }
  auto baker = VulkanBaker::create(options_.device);
  if (!baker) {
    if (options_.backend == BakeBackend::kVulkan)
      return Status::error("--backend vulkan: " + baker.error());
    backend_line_ = "cpu (auto: the Vulkan device failed: " + baker.error() + ")";
    return {};
  }
  vulkan_ = std::move(*baker);
  finisher_->useDevice(*vulkan_,
                       options_.result_passes == "vulkan" ||
                           (options_.result_passes == "auto" && vulkan_->device().type != "cpu"));
  backend_line_ = "vulkan on '" + vulkan_->device().name + "' (" + choice.reason + ")";
  return {};
}

std::string JobManager::backendLine() const {
  return backend_line_;
}

Status JobManager::assignBackend(JobRecord& job) const {
  if (vulkan_) {
    job.backend = "vulkan", job.device = vulkan_->device().name;
    return {};
  }
  job.backend = "cpu", job.device.clear();
  return {};
}

void JobManager::vulkanWorkerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    VulkanWork work;
    work_cv_.wait(lock, [&] {
      return stopping_ || scheduler_->pickVulkanWork(work, options_.vulkan_call_paths);
    });
    if (stopping_) return;
    lock.unlock();
    try {
      if (work.preview) {
        runVulkanPreview(*work.job);
      } else {
        runVulkanWork(work);
      }
    } catch (const std::exception& e) {
      failInFlight(*work.job, jobFailure(e, "baking on the Vulkan device"));
    }
    lock.lock();
  }
}

void JobManager::runVulkanWork(VulkanWork& work) {
  ActiveJob& job = *work.job;
  const auto start = std::chrono::steady_clock::now();
  std::vector<int> order;  // plan indices of the RDMs baked, first unit first
  for (size_t i : work.units) {
    const int r = job.units[i].rdm;
    if (std::find(order.begin(), order.end(), r) == order.end()) order.push_back(r);
  }
  std::vector<RdmId> ids;
  for (int r : order) ids.push_back(job.plan[size_t(r)]);
  VulkanBakeOptions options;
  options.record_slot_sets = true;
  options.cancel = &job.cancel_flag;
  auto baked = vulkan_->bake(*job.world, job.settings, ids, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!baked || baked->report.cancelled) {
    if (!baked)
      logEvent(LogLevel::kError, "job",
               {{"message", "job " + std::string(job.id) + ": " + baked.error()}});
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i : work.units) job.unit_state[i] = 0;
    job.cursor = std::min(job.cursor, work.units.front());
    if (!baked && job.failure.ok()) job.failure = baked.status();
    if (!baked) job.cancelled = true, job.cancel_flag = true;
    job.in_flight--;
    if (job.finishable()) exec_cv_.notify_all();
    return;
  }
  uint64_t texels = 0;
  for (size_t i : work.units) {
    const BakeUnit& u = job.units[i];
    texels += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  }
  std::vector<std::pair<UnitResult, Status>> done;
  for (size_t i : work.units) {
    const BakeUnit& u = job.units[i];
    const size_t k = size_t(std::find(order.begin(), order.end(), u.rdm) - order.begin());
    const RdmData& from = baked->rdms[k];
    UnitResult result;
    extractUnit(from, u, result);
    RDM_CHECK(applyUnit(result, job.storage->rdmTexels(size_t(u.rdm))));
    // Every unit carries its RDM's sets: a resumed job merges whichever units it restores.
    result.full_set = from.full_set, result.first_set = from.first_set;
    result.smooth = from.smooth_vertex;
    const double share = double(uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0)) / double(texels);
    result.rays = uint64_t(double(baked->report.rays) * share);
    result.seconds = seconds * share;
    Status saved = store_.saveUnit(job.id, result, job.local_index[i]);
    if (!saved) logEvent(LogLevel::kError, "job", {{"message", saved.message()}});
    done.emplace_back(std::move(result), saved);
  }
  metrics_.addRays(baked->report.rays);
  metrics_.addBakeSeconds(seconds);
  std::unique_lock<std::mutex> lock(mutex_);
  std::vector<size_t> finished;
  for (size_t n = 0; n < work.units.size(); ++n) {
    if (UnitScheduler::bookUnit(job, work.units[n], done[n].first, done[n].second,
                                records_.at(job.id)))
      finished.push_back(size_t(job.units[work.units[n]].rdm));
  }
  lock.unlock();
  for (size_t r : finished) job.releaseFinished(r);
  lock.lock();
  job.in_flight--;
  if (job.finishable()) exec_cv_.notify_all();
}

// The preview pass in one call; published as runPreviewUnit publishes its last unit.
void JobManager::runVulkanPreview(ActiveJob& job) {
  PreviewPass& preview = *job.preview;
  std::vector<RdmId> ids;
  for (const RdmData& d : preview.session->rdms()) ids.push_back(d.id);
  VulkanBakeOptions options;
  options.cancel = &job.cancel_flag;
  auto baked = vulkan_->bake(*job.world, preview.settings, ids, options);
  const bool ok = baked && !baked->report.cancelled;
  if (!baked)
    logEvent(LogLevel::kError, "job",
             {{"message", "job " + std::string(job.id) + ": " + baked.error()}});
  if (ok) {
    for (size_t i = 0; i < ids.size(); ++i) {
      preview.session->rdms()[i].image = std::move(baked->rdms[i].image);
      preview.session->rdms()[i].stderr_rgb = std::move(baked->rdms[i].stderr_rgb);
    }
    metrics_.addRays(baked->report.rays);
  }
  bool publish_now = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    preview.left = 0;
    if (!baked && job.failure.ok()) job.failure = baked.status();
    if (!baked) job.cancelled = true, job.cancel_flag = true;
    publish_now = ok && !job.cancelled;
  }
  // Still in flight, so the job cannot finish (and publish its final pass) before this.
  if (publish_now) publish(job, 0, preview.settings, snapshotImages(*preview.session));
  leaveFlight(job);
}

}  // namespace rdm
