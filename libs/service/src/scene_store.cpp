#include "rdm/service/scene_store.h"

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "rdm/base/clock.h"
#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"
#include "rdm/base/log.h"
#include "rdm/scene/scene_patch.h"
#include "rdm/service/resource_id.h"
#include "rdm/service/stored_file.h"

namespace rdm {
namespace {

using nlohmann::json;

// A version file's checksum sidecar: `v<N>.json.xxh3`, the 16 hex digits of the file's XXH3
// 64 and a newline, written after the version file and before meta.json names the version.
std::string checksumPath(const std::string& version_path) {
  return version_path + ".xxh3";
}

// meta.json's fields and, as "check", the XXH3 64 of their compact dump without it.
std::string metaText(const SceneInfo& info) {
  json meta = {
      {"id", info.id}, {"version", info.version}, {"seq", info.seq}, {"created", info.created}};
  meta["check"] = hashHex(contentHash(meta.dump()));
  return meta.dump() + "\n";
}

// The record of a meta.json, or nothing when it is torn or fails its check. A meta.json
// without "check" (written before checksums) is taken as it parses.
std::optional<SceneInfo> parseMeta(const std::string& id, const std::string& text) {
  try {
    json j = json::parse(text);
    if (j.contains("check")) {
      const std::string check = j.at("check").get<std::string>();
      j.erase("check");
      if (hashHex(contentHash(j.dump())) != check) return std::nullopt;
    }
    if (j.at("id").get<std::string>() != id) return std::nullopt;
    SceneInfo info{id, j.at("version").get<long long>(), j.at("seq").get<long long>(),
                   j.at("created").get<double>()};
    if (info.version < 1) return std::nullopt;
    return info;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// The version numbers of the `v<N>.json` files in `dir` (not their sidecars), rising.
std::vector<long long> versionFiles(const std::string& dir) {
  std::vector<long long> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() < 7 || name[0] != 'v' || name.compare(name.size() - 5, 5, ".json") != 0)
      continue;
    const std::string digits = name.substr(1, name.size() - 6);
    if (digits.empty() || digits.size() > 15 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    out.push_back(std::stoll(digits));
  }
  std::sort(out.begin(), out.end());
  return out;
}

constexpr const char* kTrashPrefix = ".trash-";  // scenes being deleted (SceneStore::remove)

}  // namespace

json sceneInfoJson(const SceneInfo& info) {
  return {{"id", info.id}, {"version", info.version}, {"created", info.created}};
}

Status SceneStore::load() {
  if (Status s = makeDirectories(dir_); !s) return s;
  std::error_code ec;
  std::vector<std::string> rebuild;  // scenes whose meta.json is torn or damaged
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string id = entry.path().filename().string();
    if (id.rfind(kTrashPrefix, 0) == 0) {  // a delete a crash interrupted: finish it
      std::error_code trash_ec;
      std::filesystem::remove_all(entry.path(), trash_ec);
      continue;
    }
    if (!validId(id, 's')) continue;
    auto text = readFileToString(sceneDir(id) + "/meta.json");
    if (!text) {  // never committed: an upload that failed before its first version landed
      quarantine(sceneDir(id), "meta.json is missing");
      continue;
    }
    std::optional<SceneInfo> info = parseMeta(id, *text);
    if (!info) {  // torn or damaged: rebuilt from the version files once all are loaded
      logEvent(LogLevel::kError, "corrupt",
               {{"path", sceneDir(id) + "/meta.json"},
                {"expected", "a scene record"},
                {"actual", "torn or fails its check"}});
      rebuild.push_back(id);
      continue;
    }
    auto e = std::make_shared<Entry>();
    e->info = *info;
    next_seq_ = std::max(next_seq_, e->info.seq + 1);
    scenes_[id] = e;
  }
  if (ec) return Status::error(dir_ + ": " + ec.message());
  for (const std::string& id : rebuild) rebuildMeta(id);
  return {};
}

void SceneStore::rebuildMeta(const std::string& id) {
  const std::vector<long long> versions = versionFiles(sceneDir(id));
  if (versions.empty()) {
    quarantine(sceneDir(id), "meta.json is torn and no version file is left");
    return;
  }
  // The newest version file is current; the first one's time is the upload's; the scene
  // lists as the newest, since its place among the others is lost.
  const std::string first = sceneDir(id) + "/v" + std::to_string(versions.front()) + ".json";
  std::error_code ec;
  const auto mtime = std::filesystem::last_write_time(first, ec);
  double created = nowSeconds();
  if (!ec) {
    created =
        std::chrono::duration<double>(std::chrono::file_clock::to_sys(mtime).time_since_epoch())
            .count();
  }
  auto e = std::make_shared<Entry>();
  e->info = {id, versions.back(), next_seq_++, created};
  e->oldest_on_disk = versions.front();
  const Status written = writeFileAtomic(sceneDir(id) + "/meta.json", metaText(e->info));
  logEvent(written ? LogLevel::kWarn : LogLevel::kError, "scene-meta-rebuilt",
           {{"scene", id},
            {"version", e->info.version},
            {"written", written.ok()},
            {"error", written.ok() ? "" : written.message()}});
  scenes_[id] = e;
}

Status SceneStore::writeVersion(const SceneInfo& info, const Scene& scene) {
  const std::string dir = sceneDir(info.id);
  if (Status s = makeDirectories(dir); !s) return s;
  const std::string path = dir + "/v" + std::to_string(info.version) + ".json";
  if (Status s = saveSceneFile(path, scene); !s) return s;
  auto written = readFileToString(path);  // hashed as stored (page cache): the sidecar's
  if (!written) return written.status();
  if (Status s = writeFileAtomic(checksumPath(path), hashHex(contentHash(*written)) + "\n"); !s)
    return s;
  return writeFileAtomic(dir + "/meta.json", metaText(info));
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
  const auto damaged = [&](const std::string& expected, const std::string& actual) {
    reportCorrupt(path, expected, actual, false);  // kept in place: the version stays named
    return Status::error(StatusCode::kCorrupt,
                         "scene " + id + " version " + std::to_string(version) +
                             " is damaged on disk (" + actual + "); other versions are unaffected");
  };
  if (auto sidecar = readFileToString(checksumPath(path))) {  // none: written before checksums
    const std::optional<uint64_t> expected = parseHashHex(sidecar->substr(0, 16));
    auto bytes = readFileToString(path);
    if (!bytes) return bytes.status();
    const uint64_t actual = contentHash(*bytes);
    if (!expected) return damaged("", "its checksum file is damaged");
    if (*expected != actual) return damaged(hashHex(*expected), hashHex(actual));
  }
  Expected<Scene> scene = loadSceneFile(path);
  if (!scene && scene.status().code() != StatusCode::kIo) return damaged("", scene.error());
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
  auto found = find(id, current);
  if (!found) return found.status();  // kCorrupt names the damaged version
  std::shared_ptr<const Scene> old = *found;
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
    std::filesystem::remove(checksumPath(path), ec);  // its sidecar, if any
    ++dropped;
    std::lock_guard<std::mutex> lock(mutex_);
    e->versions.erase(v);
  }
  e->oldest_on_disk = std::max<long long>(1, oldest_left);
  return dropped;
}

Status SceneStore::remove(const std::string& id) {
  std::shared_ptr<Entry> e;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = scenes_.find(id);
    if (it == scenes_.end()) return Status::notFound("no scene '" + id + "'");
    e = it->second;
  }
  std::lock_guard<std::mutex> write_lock(e->write_mutex);  // no PATCH or prune meanwhile
  const std::string trash = dir_ + "/" + kTrashPrefix + id;
  std::error_code ec;
  std::filesystem::rename(sceneDir(id), trash, ec);
  if (ec) return Status::error(StatusCode::kIo, sceneDir(id) + ": cannot delete: " + ec.message());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scenes_.erase(id);
  }
  std::filesystem::remove_all(trash, ec);  // what stays is swept at the next load()
  return {};
}

Status SceneStore::removeVersion(const std::string& id, long long version) {
  std::shared_ptr<Entry> e;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = scenes_.find(id);
    if (it == scenes_.end()) return Status::notFound("no scene '" + id + "'");
    e = it->second;
  }
  std::lock_guard<std::mutex> write_lock(e->write_mutex);
  const long long current = info(id).value_or(SceneInfo{}).version;
  const std::string path = sceneDir(id) + "/v" + std::to_string(version) + ".json";
  std::error_code ec;
  if (version < 1 || version > current || !std::filesystem::exists(path, ec)) {
    return Status::notFound("scene " + id + " has no version " + std::to_string(version) +
                            " (unknown, pruned or deleted)");
  }
  if (version == current) {
    return Status::conflict(
        "version " + std::to_string(version) + " is the current version of scene " + id +
        "; it stays while the scene exists (DELETE /v1/scenes/" + id + " deletes the scene)");
  }
  if (!std::filesystem::remove(path, ec) && ec)
    return Status::error(StatusCode::kIo, path + ": cannot delete: " + ec.message());
  std::filesystem::remove(checksumPath(path), ec);  // the version is gone without it too
  std::lock_guard<std::mutex> lock(mutex_);
  e->versions.erase(version);
  return {};
}

}  // namespace rdm
