// Versioned scenes, kept in memory and in the data directory:
//   scenes/<id>/v<N>.json   the scene at version N (docs/spec.md section 2 format)
//   scenes/<id>/v<N>.json.xxh3  the XXH3 64 of v<N>.json (16 hex digits), checked on read
//   scenes/<id>/meta.json   {"id", "version", "seq", "created", "check"}; written last, so a
//                           scene or version exists once its meta.json names it. A torn or
//                           damaged meta.json is rebuilt from the version files at load().
// Every file is written atomically (temp file + fsync + rename). Thread-safe.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/scene_diff.h"

namespace rdm {

struct SceneInfo {
  std::string id;
  long long version = 0;
  long long seq = 0;
  double created = 0.0;  // unix seconds
};

struct PatchOutcome {
  SceneInfo info;
  SceneDiff diff;  // against the previous version
};

class SceneStore {
 public:
  // `kept_versions`: how many of the newest versions prune() keeps (--max-versions).
  SceneStore(std::string data_dir, long long kept_versions)
      : dir_(std::move(data_dir) + "/scenes"), kept_versions_(kept_versions) {}
  Status load();  // reads every meta.json; versions load on demand

  // Takes the scene (a large one is not copied); get(id, 1) reads it back.
  Expected<SceneInfo> create(Scene scene);
  std::optional<SceneInfo> info(const std::string& id) const;
  std::vector<SceneInfo> list() const;  // newest first
  size_t count() const;
  // The scene at `version` (0: current): kNotFound when the scene or version is unknown or
  // was pruned, kCorrupt (logged) when its file fails its checksum or does not parse, kIo
  // when it cannot be read. Other versions are unaffected.
  Expected<std::shared_ptr<const Scene>> find(const std::string& id, long long version = 0);
  // find(), null on any failure.
  std::shared_ptr<const Scene> get(const std::string& id, long long version = 0);
  // Applies `patch` when base_version is current; kConflict when stale, kNotFound or
  // kInvalidInput as usual. `check` vets the patched scene (server limits) before it is stored.
  Expected<PatchOutcome> patch(const std::string& id, const nlohmann::json& patch,
                               const std::function<Status(const Scene&)>& check);
  // Drops, from memory and disk, the versions older than the newest kept_versions that
  // `in_use` does not name (docs/spec.md section 8.3); returns how many went. The current
  // version always stays.
  size_t prune(const std::string& id, const std::set<long long>& in_use);
  // DELETE /v1/scenes/{id}: renames scenes/<id> to scenes/.trash-<id> (one rename: a crash
  // leaves the scene whole or gone; load() sweeps the trash), forgets it, then removes the
  // files. kNotFound for an unknown scene, kIo when the rename fails (nothing changed).
  // The caller (JobManager::removeScene) has checked that no job needs it.
  Status remove(const std::string& id);
  // DELETE /v1/scenes/{id}/versions/{n}: removes version `version`'s file. kNotFound when the
  // scene or version is unknown or already gone, kConflict for the current version (it always
  // stays; delete the scene). The caller has checked that no job needs it (versionsInUse).
  Status removeVersion(const std::string& id, long long version);
  // Versions of `id` held in memory (at most kCachedVersions, the newest used).
  size_t cachedVersions(const std::string& id) const;

  long long keptVersions() const { return kept_versions_; }
  static constexpr size_t kCachedVersions = 4;

 private:
  struct Entry {
    SceneInfo info;
    std::map<long long, std::shared_ptr<const Scene>> versions;
    std::mutex write_mutex;        // serialises PATCHes (and pruning) of one scene
    long long oldest_on_disk = 1;  // no version file below it (guarded by write_mutex)
  };
  std::string sceneDir(const std::string& id) const { return dir_ + "/" + id; }
  Status writeVersion(const SceneInfo& info, const Scene& scene);
  // A scene whose meta.json is torn or damaged: current = its newest version file, listed as
  // the newest scene; meta.json written again. Without version files it is quarantined.
  void rebuildMeta(const std::string& id);
  // Caches `scene` as `version` of `e` and evicts the oldest beyond kCachedVersions.
  void cache(Entry& e, long long version, std::shared_ptr<const Scene> scene);

  std::string dir_;
  long long kept_versions_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Entry>> scenes_;
  long long next_seq_ = 1;
};

nlohmann::json sceneInfoJson(const SceneInfo& info);

}  // namespace rdm
