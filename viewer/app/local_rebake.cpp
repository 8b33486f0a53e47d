#include "local_rebake.h"

#include <atomic>
#include <chrono>
#include <mutex>

#include "rdm/atlas/incremental_baker.h"
#include "rdm/base/thread_priority.h"
#include "rdm/scene/scene_diff.h"
#include "rebake_queue.h"

namespace rdm::viewer {

struct LocalRebake::Impl : RebakeQueue {
  BakeMode mode;
  IncrementalBaker baker;  // worker-only
  std::optional<Scene> requested;
  std::optional<Scene> baked;  // the scene the last final pass was baked for
  std::atomic<bool> cancel{false};

  void run();
  void bakeOne(const Scene& scene);
};

void LocalRebake::Impl::bakeOne(const Scene& scene) {
  const auto start = std::chrono::steady_clock::now();
  IncrementalBakeOptions options;
  options.mode = mode;
  options.cancel = &cancel;
  options.on_progress = [&](int pass, int passes, const BakeProgress& p) {
    std::lock_guard<std::mutex> lock(mutex);
    live.pass = pass, live.passes = passes;
    live.fraction = p.rdms_total ? double(p.rdms_done) / double(p.rdms_total) : 0.0;
    live.eta_seconds.reset();
    if (live.fraction > 0.05 && p.seconds > 0.5)
      live.eta_seconds = p.seconds * (1.0 - live.fraction) / live.fraction;
  };
  const bool whole = !baker.hasBase();
  Status s = baker.bake(scene, options, [&](AtlasDelta delta) {
    LiveAtlas atlas = liveAtlasOf(std::move(delta), whole);
    std::lock_guard<std::mutex> lock(mutex);
    if (atlas.final) baked = scene;
    live.stale_slots = atlas.final ? std::vector<glm::ivec3>() : atlas.preview_slots;
    if (baked && requested) {
      for (const glm::ivec3& c : diffScenes(*baked, *requested).changed_slots)
        live.stale_slots.push_back(c);
    }
    atlas.received = std::chrono::steady_clock::now();
    ready.push_back(std::move(atlas));
  });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(mutex);
  live.message = s.ok() ? "baked in-process in " + std::to_string(int(seconds * 1000)) + " ms"
                        : "in-process bake: " + s.message();
}

void LocalRebake::Impl::run() {
  for (;;) {
    std::unique_lock<std::mutex> lock(mutex);
    std::optional<Scene> scene = waitForRequest(lock);
    if (!scene) return;
    cancel = false;
    live.job = "in-process", live.mode = modeName(mode);
    lock.unlock();
    bakeOne(*scene);
  }
}

LocalRebake::LocalRebake(BakeMode mode) : impl_(std::make_unique<Impl>()) {
  impl_->mode = mode;
  impl_->live.message = "in-process bake";
  Impl* raw = impl_.get();
  impl_->startWorker(
      [raw] {
        lowerThreadPriority();  // and the bake's own threads, which inherit it
        raw->run();
      },
      "in-process bake stopped: ");
}

LocalRebake::~LocalRebake() {
  impl_->cancel = true;
  impl_->stopWorker();
}

void LocalRebake::requestRebake(const Scene& scene) {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->requested = scene;
    impl_->live.stale_slots.clear();  // what differs from the last bake, until it is baked
    if (impl_->baked) impl_->live.stale_slots = diffScenes(*impl_->baked, scene).changed_slots;
    impl_->pending = scene;
  }
  impl_->wake.notify_all();
}

void LocalRebake::requestCancel() {
  impl_->cancel = true;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->pending.reset();
}

std::optional<LiveAtlas> LocalRebake::takeAtlas() {
  return impl_->takeAtlas();
}

LiveState LocalRebake::state() {
  return impl_->state();
}

}  // namespace rdm::viewer
