#include "live_rebake.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>

#include <nlohmann/json.hpp>

#include "rdm/image/exr_io.h"
#include "rdm/image/ktx2.h"
#include "rdm/scene/scene_diff.h"
#include "rdm/scene/scene_patch.h"
#include "rdm/service/client.h"
#include "rebake_queue.h"
#include "renderer.h"

namespace rdm::viewer {
namespace {

using nlohmann::json;

constexpr double kJobTimeoutSeconds = 3600.0;
constexpr double kRetrySeconds = 1.0;

using SlotKey = std::array<int, 3>;

}  // namespace

LiveAtlas liveAtlasOf(AtlasDelta delta, bool whole) {
  LiveAtlas out;
  out.is_delta = !whole, out.job = delta.job, out.pass = delta.pass, out.passes = delta.passes;
  out.final = delta.final;
  out.atlas.layout = std::move(delta.layout);
  if (whole) {
    for (const AtlasPage& p : out.atlas.layout.pages)
      out.atlas.pages.emplace_back(p.width, p.height, 4);
  }
  for (DeltaRect& r : delta.rects) {
    if (!out.final) out.preview_slots.push_back(r.entry.id.slot);
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = r.entry.faces[size_t(f)];
      if (!t.stored()) continue;
      Image face = faceTexels(r.texels, f);
      if (whole) {
        copyTexels(face, 0, 0, out.atlas.pages[size_t(t.page)], t.x, t.y, face.width, face.height);
      } else {
        out.updates.push_back({t.page, t.x, t.y, std::move(face)});
      }
    }
  }
  return out;
}

struct LiveRebake::Impl : RebakeQueue {
  std::unique_ptr<BakeClient> client;
  LiveOptions options;
  std::string scene_id;
  long long version = 1;
  Scene server_scene;  // the scene at `version` on the server

  Scene requested;                    // the latest scene asked for (edits diff against it)
  Scene converged;                    // the scene the held atlas was baked for
  std::set<SlotKey> previewed;        // held at preview quality until the final pass
  bool cancel = false;                // under `mutex`
  std::string message_before_outage;  // under `mutex`; shown again on reconnect

  // Worker-only.
  std::string last_job;  // the converged job whose atlas the viewer holds
  AtlasLayout last_layout;
  bool holds_preview = false;             // the texture holds preview rects of an unconverged job
  std::set<std::string> face_light_jobs;  // submitted jobs that bake a face light

  // Stale: slots where the requested scene differs from the one the atlas was baked for
  // (so undoing every edit clears them); RDMs at preview quality are counted. Under `mutex`.
  void updateStale() {
    live.stale_slots = diffScenes(converged, requested).changed_slots;
    live.preview_rdms = int(previewed.size());
  }
  bool stopping() {
    std::lock_guard<std::mutex> lock(mutex);
    return stop;
  }
  bool sleepFor(double seconds) {  // false when stopping
    std::unique_lock<std::mutex> lock(mutex);
    return !wake.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return stop; });
  }
  // Runs `step` until it succeeds, fails for a reason other than the network, or stop. While
  // the daemon is unreachable the message says so; once it answers, the message from before
  // the outage is back.
  template <class F>
  auto retrying(F step) -> decltype(step()) {
    for (;;) {
      auto result = step();
      if (result.ok() || resultCode(result) != StatusCode::kIo) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!live.connected) live.message = message_before_outage;
        live.connected = true;
        return result;
      }
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (live.connected) message_before_outage = live.message;
        live.connected = false;
        live.message = "daemon unreachable, keeping the last atlas; retrying: " + errorOf(result);
      }
      if (!sleepFor(kRetrySeconds)) return result;
    }
  }
  static StatusCode resultCode(const Status& s) { return s.code(); }
  template <class T>
  static StatusCode resultCode(const Expected<T>& e) {
    return e.ok() ? StatusCode::kOk : e.status().code();
  }
  static std::string errorOf(const Status& s) { return s.message(); }
  template <class T>
  static std::string errorOf(const Expected<T>& e) {
    return e.error();
  }

  Expected<std::string> submit(BakeMode mode);
  Status follow(const std::string& job, BakeMode mode);
  Status fetchFull(const std::string& job, int pass, int passes);
  Expected<Image> fetchPage(const std::string& job, const AtlasLayout& layout, int page);
  void publish(LiveAtlas atlas);
  Status patch(const Scene& target);
  Status rebake(BakeMode mode);
  void run();
};

Expected<std::string> LiveRebake::Impl::submit(BakeMode mode) {
  nlohmann::json request = {{"version", version}, {"mode", modeName(mode)}};
  if (options.face_light_spp >= 0) request["face_light"] = options.face_light_spp;
  auto job = retrying([&] { return client->submitBake(scene_id, request); });
  if (!job) return job.status();
  const std::string id = (*job)["id"].get<std::string>();
  if (job->value("face_light", 0) > 0) face_light_jobs.insert(id);
  return id;
}

void LiveRebake::Impl::publish(LiveAtlas atlas) {
  std::lock_guard<std::mutex> lock(mutex);
  if (atlas.final) {
    converged = server_scene, previewed.clear();
  } else {
    for (const glm::ivec3& s : atlas.preview_slots) previewed.insert({s.x, s.y, s.z});
  }
  updateStale();
  atlas.received = std::chrono::steady_clock::now();
  ready.push_back(std::move(atlas));
}

// Page `page` of a succeeded job as stored (R, G, B, Z; a bc6h job's blocks decoded).
Expected<Image> LiveRebake::Impl::fetchPage(const std::string& job, const AtlasLayout& layout,
                                            int page) {
  const std::string query = "?page=" + std::to_string(page);
  if (layout.radiance != RadianceFormat::kBc6h) {
    auto bytes = retrying([&] { return client->download(job, "atlas.exr" + query); });
    if (!bytes) return bytes.status();
    return decodeExr(*bytes, kRgbzChannels);
  }
  auto blocks = retrying([&] { return client->download(job, "atlas.ktx2" + query); });
  if (!blocks) return blocks.status();
  auto depth = retrying([&] { return client->download(job, "depth.exr" + query); });
  if (!depth) return depth.status();
  auto ktx2 = decodeKtx2(*blocks);
  if (!ktx2) return ktx2.status();
  auto z = decodeExr(*depth, {"Z"});
  if (!z) return z.status();
  return joinBc6hAtlasPage(layout, page,
                           Bc6hImage{ktx2->width, ktx2->height, std::move(ktx2->data)}, *z);
}

Status LiveRebake::Impl::fetchFull(const std::string& job, int pass, int passes) {
  auto index = retrying([&] { return client->download(job, "index.json"); });
  if (!index) return index.status();
  auto layout = parseIndexJson(*index);
  if (!layout) return layout.status();
  LiveAtlas out;
  out.atlas.layout = std::move(*layout);
  for (size_t p = 0; p < out.atlas.layout.pages.size(); ++p) {
    auto page = fetchPage(job, out.atlas.layout, int(p));
    if (!page) return page.status();
    restoreRadiance(out.atlas.layout, int(p), *page);
    out.atlas.pages.push_back(std::move(*page));
  }
  if (face_light_jobs.count(job)) {
    auto bytes = retrying([&] { return client->download(job, kFaceLightFile); });
    if (!bytes) return bytes.status();
    auto light = decodeFaceLight(*bytes, "job " + job + " " + kFaceLightFile);
    if (!light) return light.status();
    out.face_light = std::move(*light);
  }
  out.job = job, out.pass = pass, out.passes = passes, out.final = true;
  last_job = job, last_layout = out.atlas.layout, holds_preview = false;
  publish(std::move(out));
  return {};
}

// Follows a job pass by pass (long polls), publishing each pass's delta; on cancel or failure
// restores the last converged atlas when preview rects were shown.
Status LiveRebake::Impl::follow(const std::string& id, BakeMode mode) {
  const auto start = std::chrono::steady_clock::now();
  int shown = 0;  // passes published to the window
  bool cancel_sent = false;
  bool whole = last_job.empty() || mode == BakeMode::kFull;
  for (;;) {
    // A whole atlas is read from the job's files, so wait for the job to end.
    const int want = whole ? 16 : shown + 1;
    auto job = retrying([&] { return client->jobProgress(id, 1.0, want); });
    if (!job) return job.status();
    bool send_cancel = false;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (stop) return Status::error(StatusCode::kCancelled, "stopped");
      live.job = id, live.mode = modeName(mode), live.busy = !job->terminal();
      live.pass = std::min(job->passes_done, job->passes_total - 1),
      live.passes = job->passes_total;
      live.fraction = job->fraction, live.eta_seconds = job->eta_seconds;
      live.phase = job->terminal() ? std::string() : job->phase;
      if (cancel && !cancel_sent && !job->terminal()) send_cancel = cancel_sent = true;
    }
    // A failed cancel (the job just ended) changes nothing: the next poll sees the end.
    if (send_cancel) (void)client->cancelJob(id);
    if (job->state == "failed" || job->state == "cancelled") {
      if (holds_preview && !last_job.empty()) {
        if (Status s = fetchFull(last_job, 0, 1); !s.ok()) return s;
      }
      std::lock_guard<std::mutex> lock(mutex);
      previewed.clear();
      cancel = false;
      return Status::error(
          StatusCode::kCancelled,
          "job " + id + " " + job->state + (job->error.empty() ? "" : ": " + job->error));
    }
    if (whole) {
      if (job->succeeded()) return fetchFull(id, job->passes_total - 1, job->passes_total);
    } else if (job->passes_done > shown) {
      auto delta = retrying([&] { return client->fetchDelta(id, last_job, job->passes_done - 1); });
      if (!delta && delta.status().code() == StatusCode::kConflict) {
        whole = true;  // no delta chains (the pages grew): the whole atlas once the job ends
        if (job->succeeded()) return fetchFull(id, job->passes_total - 1, job->passes_total);
        continue;
      }
      if (!delta) return delta.status();
      shown = delta->pass + 1;
      holds_preview = !delta->final;
      if (delta->final) last_job = id, last_layout = delta->layout;
      const int passes = delta->passes;
      publish(liveAtlasOf(std::move(*delta), false));
      if (shown >= passes) return {};
    }
    if (std::chrono::steady_clock::now() - start >
        std::chrono::duration<double>(kJobTimeoutSeconds))
      return Status::error(StatusCode::kIo, "bake job " + id + " timed out");
  }
}

Status LiveRebake::Impl::patch(const Scene& target) {
  const json body = makeScenePatch(server_scene, target, version);
  auto reply = retrying([&] { return client->patchScene(scene_id, body); });
  if (!reply) return reply.status();
  version = (*reply).at("version").get<long long>();
  server_scene = target;
  return {};
}

Status LiveRebake::Impl::rebake(BakeMode mode) {
  auto job = submit(mode);
  if (!job && mode != BakeMode::kFull && job.status().code() == StatusCode::kConflict)
    job = submit(mode = BakeMode::kFull);  // no compatible base: bake whole
  if (!job) return job.status();
  setMessage(std::string("live: ") + modeName(mode) + " bake " + *job);
  return follow(*job, mode);
}

void LiveRebake::Impl::run() {
  Status first = rebake(BakeMode::kFull);  // the base of the incremental ones
  if (!first.ok()) {  // the window says "not baked" (no atlas) until a request bakes whole
    std::lock_guard<std::mutex> done(mutex);
    live.failed = first.code() != StatusCode::kCancelled;
    live.message = "live: " + first.message();
  }
  for (;;) {
    std::unique_lock<std::mutex> lock(mutex);
    std::optional<Scene> target = waitForRequest(lock);
    if (!target) return;
    cancel = false;
    live.failed = false;
    lock.unlock();
    if (Status s = patch(*target); !s.ok()) {
      std::lock_guard<std::mutex> done(mutex);
      live.failed = true;
      live.message = "live: PATCH failed: " + s.message();
      continue;
    }
    Status s = rebake(last_job.empty() ? BakeMode::kFull : options.mode);
    std::lock_guard<std::mutex> done(mutex);
    live.failed = !s.ok() && s.code() != StatusCode::kCancelled;
    live.message = s.ok() ? "live: scene version " + std::to_string(version) + " up to date"
                          : "live: " + s.message();
  }
}

LiveRebake::LiveRebake(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LiveRebake::~LiveRebake() {
  // The worker notices `stop` within one long poll (1 s) or one HTTP request.
  impl_->stopWorker();
}

Status applyLiveAtlas(Renderer& renderer, LiveAtlas& update) {
  // The pages move to the renderer; the layout stays for the caller's accounting.
  Status s = update.is_delta
                 ? renderer.applyAtlasDelta(update.atlas.layout, update.updates)
                 : renderer.setAtlas({update.atlas.layout, std::move(update.atlas.pages)});
  if (s.ok() && update.face_light) s = renderer.setFaceLight(std::move(*update.face_light));
  return s;
}

Expected<std::unique_ptr<LiveRebake>> LiveRebake::connect(const std::string& url,
                                                          const Scene& scene,
                                                          const LiveOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  std::string token = options.token;
  if (token.empty() && std::getenv("RDM_TOKEN")) token = std::getenv("RDM_TOKEN");
  auto client = BakeClient::connect(url, token);
  if (!client) return client.status();
  impl->client = std::move(*client);
  auto uploaded = impl->client->uploadScene(sceneToJson(scene));
  if (!uploaded) return Status::error(uploaded.status().code(), "--server: " + uploaded.error());
  impl->scene_id = (*uploaded)["id"];
  impl->version = (*uploaded)["version"].get<long long>();
  impl->server_scene = scene;
  impl->requested = scene;
  impl->converged = scene;
  impl->live.message = "live: uploaded scene " + impl->scene_id;
  impl->live.busy = true;
  Impl* raw = impl.get();
  // Every step returns a Status; the worker's catch only keeps a library exception (e.g.
  // from nlohmann::json on a malformed reply) from ending the process.
  impl->startWorker([raw] { raw->run(); }, "live: stopped after an internal error: ");
  return std::unique_ptr<LiveRebake>(new LiveRebake(std::move(impl)));
}

void LiveRebake::requestRebake(const Scene& scene) {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->requested = scene;
    impl_->updateStale();
    impl_->pending = scene;
    impl_->live.busy = true, impl_->live.failed = false;
  }
  impl_->wake.notify_all();
}

void LiveRebake::requestCancel() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->cancel = true;
  impl_->pending.reset();
}

std::optional<LiveAtlas> LiveRebake::takeAtlas() {
  return impl_->takeAtlas();
}

LiveState LiveRebake::state() {
  return impl_->state();
}

}  // namespace rdm::viewer
