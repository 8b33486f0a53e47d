#include "rdm/service/scene_store.h"

#include <filesystem>

#include "rdm/base/clock.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene_patch.h"
#include "rdm/service/resource_id.h"

namespace rdm {
namespace {

using nlohmann::json;

}  // namespace

json sceneInfoJson(const SceneInfo& info) {
  return {{"id", info.id}, {"version", info.version}, {"created", info.created}};
}

Status SceneStore::load() {
  if (Status s = makeDirectories(dir_); !s) return s;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string id = entry.path().filename().string();
    if (!validId(id, 's')) continue;
    auto text = readFileToString(sceneDir(id) + "/meta.json");
    if (!text) {  // never committed: an upload that failed before its first version landed
      quarantine(sceneDir(id), "meta.json is missing");
      continue;
    }
    try {
      json j = json::parse(*text);
      auto e = std::make_shared<Entry>();
      e->info = {id, j.at("version").get<long long>(), j.at("seq").get<long long>(),
                 j.at("created").get<double>()};
      next_seq_ = std::max(next_seq_, e->info.seq + 1);
      scenes_[id] = e;
    } catch (const std::exception&) {
      quarantine(sceneDir(id), "meta.json is torn or not a scene record");
    }
  }
  if (ec) return Status::error(dir_ + ": " + ec.message());
  return {};
}

Status SceneStore::writeVersion(const SceneInfo& info, const Scene& scene) {
  const std::string dir = sceneDir(info.id);
  if (Status s = makeDirectories(dir); !s) return s;
  if (Status s = saveSceneFile(dir + "/v" + std::to_string(info.version) + ".json", scene); !s)
    return s;
  json meta = {
      {"id", info.id}, {"version", info.version}, {"seq", info.seq}, {"created", info.created}};
  return writeFileAtomic(dir + "/meta.json", meta.dump() + "\n");
}

Expected<SceneInfo> SceneStore::create(Scene scene) {
  auto e = std::make_shared<Entry>();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    e->info = {newId('s'), 1, next_seq_++, nowSeconds()};
  }
  if (Status s = writeVersion(e->info, scene); !s) {
    std::error_code ec;
    std::filesystem::remove_all(sceneDir(e->info.id), ec);  // no empty or torn scene is left
    return s;
  }
  e->versions[1] = std::make_shared<const Scene>(std::move(scene));
  std::lock_guard<std::mutex> lock(mutex_);
  scenes_[e->info.id] = e;
  return e->info;
}

std::optional<SceneInfo> SceneStore::info(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = scenes_.find(id);
  if (it == scenes_.end()) return std::nullopt;
  return it->second->info;
}

std::vector<SceneInfo> SceneStore::list() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SceneInfo> out;
  for (const auto& [id, e] : scenes_) out.push_back(e->info);
  std::sort(out.begin(), out.end(),
            [](const SceneInfo& a, const SceneInfo& b) { return a.seq > b.seq; });
  return out;
}

size_t SceneStore::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return scenes_.size();
}

std::shared_ptr<const Scene> SceneStore::get(const std::string& id, long long version) {
  Expected<std::shared_ptr<const Scene>> scene = find(id, version);
  return scene ? *scene : nullptr;
}

Expected<std::shared_ptr<const Scene>> SceneStore::find(const std::string& id, long long version) {
  const auto unknown = [&] {
    return Status::notFound("scene " + id + " has no version " + std::to_string(version));
  };
  std::shared_ptr<Entry> e;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = scenes_.find(id);
    if (it == scenes_.end()) return unknown();
    e = it->second;
    if (version == 0) version = e->info.version;
    if (version < 1 || version > e->info.version) return unknown();
    auto v = e->versions.find(version);
    if (v != e->versions.end()) return v->second;
  }
  const std::string path = sceneDir(id) + "/v" + std::to_string(version) + ".json";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) && !ec) return unknown();  // pruned
  Expected<Scene> scene = loadSceneFile(path);
  if (!scene) return scene.status();
  std::shared_ptr<const Scene> shared = std::make_shared<const Scene>(std::move(*scene));
  std::lock_guard<std::mutex> lock(mutex_);
  cache(*e, version, shared);
  return shared;
}

Expected<PatchOutcome> SceneStore::patch(const std::string& id, const json& body,
                                         const std::function<Status(const Scene&)>& check) {
  std::shared_ptr<Entry> e;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = scenes_.find(id);
    if (it == scenes_.end()) return Status::notFound("no scene '" + id + "'");
    e = it->second;
  }
  if (!body.is_object() || !body.contains("base_version")) {
    return Status::invalidField("base_version", "required");
  }
  if (!body["base_version"].is_number_integer()) {
    return Status::invalidField("base_version", "expected an integer");
  }
  std::lock_guard<std::mutex> write_lock(e->write_mutex);
  const long long current = info(id)->version;
  const long long base = body["base_version"].get<long long>();
  if (base != current) {
    return Status::conflict("base_version " + std::to_string(base) +
                                " is stale: the scene is at version " + std::to_string(current),
                            "base_version");
  }
  std::shared_ptr<const Scene> old = get(id, current);
  if (!old)
    return Status::error("scene " + id + " version " + std::to_string(current) + " is unreadable");
  if (scenePatchIsEmpty(body)) return PatchOutcome{info(id).value(), SceneDiff{}};
  auto patched = applyScenePatch(*old, body);
  if (!patched) return patched.status();
  Scene& scene = *patched;
  if (Status s = check(scene); !s) return s;
  SceneInfo next = e->info;
  next.version = current + 1;
  if (Status s = writeVersion(next, scene); !s) return s;
  PatchOutcome out{next, diffScenes(*old, scene)};
  std::lock_guard<std::mutex> lock(mutex_);
  e->info = next;
  cache(*e, next.version, std::make_shared<const Scene>(std::move(scene)));
  return out;
}

void SceneStore::cache(Entry& e, long long version, std::shared_ptr<const Scene> scene) {
  e.versions[version] = std::move(scene);
  while (e.versions.size() > kCachedVersions) e.versions.erase(e.versions.begin());
}

size_t SceneStore::cachedVersions(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = scenes_.find(id);
  return it == scenes_.end() ? 0 : it->second->versions.size();
}

size_t SceneStore::prune(const std::string& id, const std::set<long long>& in_use) {
  std::shared_ptr<Entry> e;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = scenes_.find(id);
    if (it == scenes_.end()) return 0;
    e = it->second;
  }
  std::lock_guard<std::mutex> write_lock(e->write_mutex);  // no PATCH writes meanwhile
  const long long oldest_kept = info(id)->version - kept_versions_ + 1;
  long long oldest_left = oldest_kept;
  size_t dropped = 0;
  for (long long v = e->oldest_on_disk; v < oldest_kept; ++v) {
    const std::string path = sceneDir(id) + "/v" + std::to_string(v) + ".json";
    std::error_code ec;
    if (in_use.count(v) || (!std::filesystem::remove(path, ec) && ec)) {
      oldest_left = std::min(oldest_left, v);  // kept, or not removable now: try again later
      continue;
    }
    ++dropped;
    std::lock_guard<std::mutex> lock(mutex_);
    e->versions.erase(v);
  }
  e->oldest_on_disk = std::max<long long>(1, oldest_left);
  return dropped;
}

}  // namespace rdm
