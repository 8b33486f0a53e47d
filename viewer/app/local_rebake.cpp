#include "local_rebake.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>

#include "rdm/atlas/incremental_baker.h"
#include "rdm/base/thread_priority.h"
#include "rdm/scene/scene_diff.h"
#include "rebake_queue.h"

namespace rdm::viewer {

struct LocalRebake::Impl : RebakeQueue {
  BakeMode mode;
  std::optional<LocalSeed> seed;  // taken by the worker before its first bake
  IncrementalBaker baker;         // worker-only
  std::optional<Scene> requested;
  std::optional<Scene> baked;  // the scene the last final pass was baked for
  std::atomic<bool> cancel{false};

  void run();
  void seedBaker();
  void bakeOne(const Scene& scene);
};

void LocalRebake::Impl::seedBaker() {
  Status s = baker.seedFromAtlas(seed->scene, seed->atlas_dir);
  std::lock_guard<std::mutex> lock(mutex);
  if (s.ok()) {
    baked = seed->scene;
    live.message = "in-process bakes start from the atlas in " + seed->atlas_dir;
  } else {
    live.message = "the first in-process bake bakes every RDM: " + s.message();
  }
  std::printf("%s\n", live.message.c_str());
  std::fflush(stdout);
  seed.reset();
}

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
    live.preview_rdms = int(atlas.preview_slots.size());
    live.stale_slots.clear();
    if (baked && requested) live.stale_slots = diffScenes(*baked, *requested).changed_slots;
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
  if (seed) seedBaker();
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

LocalRebake::LocalRebake(BakeMode mode, std::optional<LocalSeed> seed)
    : impl_(std::make_unique<Impl>()) {
  impl_->mode = mode;
  impl_->seed = std::move(seed);
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
