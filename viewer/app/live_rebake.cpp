#include "live_rebake.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <map>

#include <nlohmann/json.hpp>

#include "rdm/client.h"
#include "rdm/exr_io.h"

namespace rdm::viewer {
namespace {

using nlohmann::json;

constexpr double kJobTimeoutSeconds = 3600.0;

// Placements by slot, for the edit diff.
std::map<std::array<int, 3>, Placement> placementsBySlot(const Scene& scene) {
  std::map<std::array<int, 3>, Placement> out;
  for (const Placement& p : scene.placements) out[p.at] = p;
  return out;
}

// SPEC 8 PATCH body taking the server's scene `from` (at `base_version`) to `to`: new or
// redefined blocks, changed or appended palette entries, and one edit per changed slot.
// Blocks are never deleted (an unused block is harmless).
json patchBody(const Scene& from, const Scene& to, long long base_version) {
  const json to_json = json::parse(sceneToJson(to));
  json body = {{"base_version", base_version}};
  json blocks = json::object(), palette = json::object(), edits = json::array();
  for (const auto& [name, block] : to.blocks) {
    const auto it = from.blocks.find(name);
    if (it == from.blocks.end() || it->second != block) blocks[name] = to_json["blocks"][name];
  }
  for (size_t i = 0; i < to.palette.size(); ++i) {
    if (i >= from.palette.size() || from.palette[i] != to.palette[i]) {
      palette[std::to_string(i + 1)] = to_json["palette"][i];
    }
  }
  const auto before = placementsBySlot(from), after = placementsBySlot(to);
  for (const auto& [at, p] : after) {
    const auto it = before.find(at);
    if (it == before.end() || !(it->second == p))
      edits.push_back({{"at", at}, {"block", p.block}, {"rot", p.rot}});
  }
  for (const auto& [at, p] : before) {
    if (!after.count(at)) edits.push_back({{"at", at}, {"block", nullptr}});
  }
  if (!blocks.empty()) body["blocks"] = blocks;
  if (!palette.empty()) body["palette"] = palette;
  if (!edits.empty()) body["edits"] = edits;
  return body;
}

}  // namespace

struct LiveRebake::Impl {
  std::unique_ptr<BakeClient> client;
  std::string scene_id;
  long long version = 1;
  Scene server_scene;  // the scene at `version` on the server

  std::mutex mutex;
  std::condition_variable wake;
  std::optional<Scene> pending;
  std::optional<LiveAtlas> ready;
  std::string last_job;  // the job whose atlas the viewer holds
  AtlasLayout last_layout;
  std::string status;
  bool stop = false;
  std::thread worker;

  void setStatus(const std::string& s) {
    std::lock_guard<std::mutex> lock(mutex);
    status = s;
  }
  Expected<LiveAtlas> bake(const std::string& mode);
  Expected<LiveAtlas> fetchDelta(const std::string& job, AtlasLayout layout);
  Expected<LiveAtlas> fetchFull(const std::string& job, AtlasLayout layout);
  Status patch(const Scene& target);
  void run();
};

Expected<LiveAtlas> LiveRebake::Impl::bake(const std::string& mode) {
  auto job = client->submitBake(scene_id, {{"version", version}, {"mode", mode}});
  if (!job) return job.status();
  const std::string id = (*job)["id"];
  setStatus("live: " + mode + " bake " + id + " queued");
  // Polls (rather than BakeClient::waitForJob) so that closing the window never waits for
  // a long bake: `stop` ends the wait within one poll interval.
  const auto start = std::chrono::steady_clock::now();
  json state;
  for (;;) {
    auto j = client->job(id);
    if (!j) return j.status();
    state = *j;
    const std::string name = state.value("state", "?");
    if (name == "succeeded" || name == "failed" || name == "cancelled") break;
    const double fraction =
        state.contains("progress") ? state["progress"].value("fraction", 0.0) : 0.0;
    setStatus("live: " + mode + " bake " + id + " " + name + " " +
              std::to_string(int(100.0 * fraction)) + " %");
    std::unique_lock<std::mutex> lock(mutex);
    if (wake.wait_for(lock, std::chrono::milliseconds(250), [&] { return stop; })) {
      return Status::error("stopped");
    }
    if (std::chrono::steady_clock::now() - start >
        std::chrono::duration<double>(kJobTimeoutSeconds)) {
      return Status::error("bake job " + id + " timed out");
    }
  }
  if (state["state"] != "succeeded")
    return Status::error("bake job " + id + " " + state["state"].dump());
  auto index = client->download(id, "index.json");
  if (!index) return index.status();
  auto layout = parseIndexJson(*index);
  if (!layout) return layout.status();
  const bool same_pages =
      !last_job.empty() && layout->pages.size() == last_layout.pages.size() &&
      std::equal(layout->pages.begin(), layout->pages.end(), last_layout.pages.begin(),
                 [](const AtlasPage& a, const AtlasPage& b) {
                   return a.width == b.width && a.height == b.height;
                 });
  auto result = mode != "full" && same_pages ? fetchDelta(id, *layout) : fetchFull(id, *layout);
  if (!result) return result;
  result->job = id;
  last_job = id;
  last_layout = result->atlas.layout;
  return result;
}

Expected<LiveAtlas> LiveRebake::Impl::fetchFull(const std::string& id, AtlasLayout layout) {
  LiveAtlas out;
  out.atlas.layout = std::move(layout);
  for (size_t p = 0; p < out.atlas.layout.pages.size(); ++p) {
    auto bytes = client->download(id, "atlas.exr?page=" + std::to_string(p));
    if (!bytes) return bytes.status();
    auto page = decodeExr(*bytes, {"R", "G", "B", "Z"});
    if (!page) return page.status();
    out.atlas.pages.push_back(std::move(*page));
  }
  return out;
}

Expected<LiveAtlas> LiveRebake::Impl::fetchDelta(const std::string& id, AtlasLayout layout) {
  auto body = client->download(id, "delta?from=" + last_job);
  if (!body) return body.status();
  LiveAtlas out;
  out.is_delta = true;
  out.atlas.layout = std::move(layout);
  try {
    const json delta = json::parse(*body);
    for (const char* kind : {"added", "changed"}) {
      for (const json& e : delta.at(kind)) {
        const auto slot = e.at("slot");
        const std::string name = "rdms/" + std::to_string(slot[0].get<int>()) + "," +
                                 std::to_string(slot[1].get<int>()) + "," +
                                 std::to_string(slot[2].get<int>()) + "/" +
                                 std::to_string(e.at("level").get<int>()) + ".exr";
        auto bytes = client->download(id, name);
        if (!bytes) return bytes.status();
        auto texels = decodeExr(*bytes, {"R", "G", "B", "Z"});
        if (!texels) return texels.status();
        out.updates.push_back({e.at("page").get<int>(), e.at("rect")[0].get<int>(),
                               e.at("rect")[1].get<int>(), std::move(*texels)});
      }
    }
  } catch (const std::exception& e) {
    return Status::error(std::string("delta of job ") + id + ": " + e.what());
  }
  return out;
}

Status LiveRebake::Impl::patch(const Scene& target) {
  auto reply =
      client->patch("/v1/scenes/" + scene_id, patchBody(server_scene, target, version).dump());
  if (!reply) return reply.status();
  if (!reply->ok()) return Status::error(describeHttpError(*reply));
  version = json::parse(reply->body).at("version").get<long long>();
  server_scene = target;
  return Status();
}

void LiveRebake::Impl::run() {
  std::string mode = "full";  // the first bake is the base of the incremental ones
  for (bool first = true;; first = false) {
    if (!first) {
      std::unique_lock<std::mutex> lock(mutex);
      wake.wait(lock, [&] { return stop || pending.has_value(); });
      if (stop) return;
      Scene target = std::move(*pending);
      pending.reset();
      lock.unlock();
      if (Status s = patch(target); !s.ok()) {
        setStatus("live: PATCH failed: " + s.message());
        continue;
      }
    }
    auto atlas = bake(mode);
    std::lock_guard<std::mutex> lock(mutex);
    if (stop) return;
    if (!atlas) {
      status = "live: " + atlas.error();
      continue;
    }
    status = "live: scene version " + std::to_string(version) + " baked (" + mode + ")";
    ready = std::move(*atlas);
    mode = "fast";
  }
}

LiveRebake::LiveRebake(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LiveRebake::~LiveRebake() {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->stop = true;
  }
  impl_->wake.notify_all();
  // The worker notices `stop` within one poll interval or one HTTP request.
  if (impl_->worker.joinable()) impl_->worker.join();
}

Expected<std::unique_ptr<LiveRebake>> LiveRebake::connect(const std::string& url,
                                                          const Scene& scene) {
  auto impl = std::make_unique<Impl>();
  const char* token = std::getenv("RDM_TOKEN");
  auto client = BakeClient::connect(url, token ? token : "");
  if (!client) return client.status();
  impl->client = std::move(*client);
  auto uploaded = impl->client->uploadScene(sceneToJson(scene));
  if (!uploaded) return Status::error("--server " + url + ": " + uploaded.error());
  impl->scene_id = (*uploaded)["id"];
  impl->version = (*uploaded)["version"].get<long long>();
  impl->server_scene = scene;
  impl->status = "live: uploaded scene " + impl->scene_id;
  Impl* raw = impl.get();
  impl->worker = std::thread([raw] { raw->run(); });
  return std::unique_ptr<LiveRebake>(new LiveRebake(std::move(impl)));
}

void LiveRebake::requestRebake(const Scene& scene) {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->pending = scene;
  }
  impl_->wake.notify_all();
}

std::optional<LiveAtlas> LiveRebake::takeAtlas() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::optional<LiveAtlas> out = std::move(impl_->ready);
  impl_->ready.reset();
  return out;
}

std::string LiveRebake::statusLine() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->status;
}

}  // namespace rdm::viewer
