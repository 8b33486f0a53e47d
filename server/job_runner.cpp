// JobManager::prepare and ::finalize: turning a job record into scheduled work units, and
// finished units (plus RDMs copied from the base job) into the atlas.
#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include "active_job.h"
#include "job_manager.h"
#include "rdm/atlas.h"
#include "rdm/atlas_incremental.h"
#include "rdm/exr_io.h"
#include "rdm/file_util.h"

namespace rdm::server {
namespace {

struct Selection {
  std::vector<RdmId> plan;
  int changed_slots = 0;
  bool dirty_all = false;
};

std::variant<Selection, std::string> selectPlan(const JobRecord& job, const std::vector<RdmId>& all,
                                                const VoxelWorld& world, SceneStore& scenes,
                                                const JobStore& store, const JobRecord& base) {
  auto base_records = store.loadRdmRecords(base.id);
  if (!base_records) return std::string("base job " + base.id + ": rdms.bin missing or corrupt");
  auto base_scene = scenes.get(job.scene_id, base.scene_version);
  auto target_scene = scenes.get(job.scene_id, job.scene_version);
  if (!base_scene || !target_scene) return std::string("scene version missing");
  SceneDiff diff = diffScenes(*base_scene, *target_scene);
  if (!(base.settings == job.settings))
    diff.dirty_all = true, diff.global_changes.push_back("settings");
  const bool emitters = emittersDiffer(buildWorld(*base_scene), world);
  RebakeSelection sel = selectRebake(job.mode, diff, emitters, world, all, *base_records);
  return Selection{sel.rebake, int(diff.changed_slots.size()), diff.dirty_all};
}

std::vector<int> localIndices(const std::vector<BakeUnit>& units, size_t rdm_count) {
  std::vector<int> next(rdm_count, 0), local;
  for (const BakeUnit& u : units) local.push_back(next[size_t(u.rdm)]++);
  return local;
}

// Restores finished units from disk; returns how many.
uint64_t restoreUnits(ActiveJob& job, const JobStore& store, JobRecord& record) {
  std::map<std::tuple<int, int, int, int>, size_t> by_key;
  for (size_t i = 0; i < job.units.size(); ++i) {
    const BakeUnit& u = job.units[i];
    by_key[{u.rdm, u.face, u.x0, u.y0}] = i;
  }
  uint64_t restored = 0;
  for (UnitResult& r : store.loadUnits(job.id)) {
    auto it = by_key.find({r.unit.rdm, r.unit.face, r.unit.x0, r.unit.y0});
    if (it == by_key.end() || job.unit_state[it->second] != 0) continue;
    const BakeUnit& u = job.units[it->second];
    if (u.x1 != r.unit.x1 || u.y1 != r.unit.y1 || !(job.plan[size_t(u.rdm)] == r.id)) continue;
    if (!applyUnit(r, job.storage->rdms()[size_t(u.rdm)])) continue;
    job.unit_state[it->second] = 2;
    job.units_left[size_t(u.rdm)]--;
    RdmRecord& rec = job.records[size_t(u.rdm)];
    rec.full_set.insert(rec.full_set.end(), r.full_set.begin(), r.full_set.end());
    rec.first_set.insert(rec.first_set.end(), r.first_set.begin(), r.first_set.end());
    rec.smooth = rec.smooth || r.smooth;
    record.texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
    record.rays += r.rays;
    record.bake_seconds += r.seconds;
    ++restored;
  }
  for (RdmRecord& rec : job.records) {
    std::sort(rec.full_set.begin(), rec.full_set.end());
    rec.full_set.erase(std::unique(rec.full_set.begin(), rec.full_set.end()), rec.full_set.end());
    std::sort(rec.first_set.begin(), rec.first_set.end());
    rec.first_set.erase(std::unique(rec.first_set.begin(), rec.first_set.end()),
                        rec.first_set.end());
  }
  while (job.cursor < job.units.size() && job.unit_state[job.cursor] != 0) ++job.cursor;
  return restored;
}

}  // namespace

std::variant<std::shared_ptr<ActiveJob>, std::string> JobManager::prepare(const JobRecord& record) {
  auto job = std::make_shared<ActiveJob>();
  job->id = record.id, job->mode = record.mode, job->seq = record.seq,
  job->settings = record.settings;
  job->scene = scenes_.get(record.scene_id, record.scene_version);
  if (!job->scene) return std::string("scene " + record.scene_id + " version missing");
  job->world = std::make_unique<VoxelWorld>(buildWorld(*job->scene));
  job->all = listRdms(*job->world, job->settings);
  JobRecord update = record;
  update.rays = 0, update.texels_done = 0, update.bake_seconds = 0.0;
  if (auto plan = store_.loadPlan(record.id)) {  // resuming: the plan is fixed
    job->plan = std::move(*plan);
  } else if (record.mode == BakeMode::kFull) {
    job->plan = job->all;
  } else {
    std::optional<JobRecord> base = get(record.base_job);
    if (!base) return std::string("base job " + record.base_job + " unknown");
    auto sel = selectPlan(record, job->all, *job->world, scenes_, store_, *base);
    if (auto* e = std::get_if<std::string>(&sel)) return *e;
    Selection& s = std::get<Selection>(sel);
    job->plan = std::move(s.plan);
    update.changed_slots = s.changed_slots, update.dirty_all = s.dirty_all;
  }
  if (Status s = store_.savePlan(record.id, job->plan); !s) return s.message();
  BakeOptions options;
  options.threads = 1;
  options.record_slot_sets = true;
  job->storage = std::make_unique<BakeSession>(*job->world, job->settings, job->plan, options);
  job->units = job->storage->units();
  job->local_index = localIndices(job->units, job->plan.size());
  job->unit_state.assign(job->units.size(), 0);
  job->units_left.assign(job->plan.size(), 0);
  for (const BakeUnit& u : job->units) job->units_left[size_t(u.rdm)]++;
  job->records.resize(job->plan.size());
  for (size_t r = 0; r < job->plan.size(); ++r)
    job->records[r].id = job->plan[r], job->records[r].origin_job = record.id;
  update.units_restored = restoreUnits(*job, store_, update);
  update.units_done = update.units_restored;
  update.rdms_scene = int(job->all.size());
  update.rdms_rebake = int(job->plan.size());
  update.rdms_copied = int(job->all.size() - job->plan.size());
  update.units_total = job->units.size();
  update.texels_total = 0;
  for (const BakeUnit& u : job->units)
    update.texels_total += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  EffectSet effects = sceneEffects(*job->world);
  update.effects_simulated = effects.describeSimulated();
  update.effects_skipped = effects.describeSkipped();
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& live = jobs_[record.id];
  const bool cancel = live.cancel_requested;
  live = update;
  live.cancel_requested = cancel;
  return job;
}

namespace {

// The copied RDMs' texels, cut out of the base job's atlas pages.
Status copyFromBase(const JobStore& store, const std::string& base_id,
                    const std::vector<RdmId>& copy, std::vector<RdmData>& data,
                    std::vector<RdmRecord>& records, AtlasLayout& base_layout) {
  auto index = readFileToString(store.outDir(base_id) + "/index.json");
  if (!index) return index.status();
  auto layout = parseIndexJson(*index);
  if (!layout) return layout.status();
  base_layout = *layout;
  auto base_records = store.loadRdmRecords(base_id);
  if (!base_records) return Status::error("base job " + base_id + ": rdms.bin missing");
  std::vector<Image> pages;
  for (size_t p = 0; p < layout->pages.size(); ++p) {
    auto page =
        readExr(store.outDir(base_id) + "/" + atlasPageFileName(int(p)), {"R", "G", "B", "Z"});
    if (!page) return page.status();
    pages.push_back(std::move(*page));
  }
  std::map<std::tuple<int, int, int, int>, const RdmRecord*> by_key;
  for (const RdmRecord& r : *base_records)
    by_key[{r.id.slot.x, r.id.slot.y, r.id.slot.z, r.id.level}] = &r;
  for (const RdmId& id : copy) {
    const AtlasEntry* e = layout->find(id.slot, id.level);
    auto rec = by_key.find({id.slot.x, id.slot.y, id.slot.z, id.level});
    if (!e || rec == by_key.end()) return Status::error("base job lacks a copied RDM");
    RdmData d;
    d.id = id;
    d.image = Image(2 * id.size, 3 * id.size, 4);
    const Image& page = pages[size_t(e->page)];
    for (int y = 0; y < d.image.height; ++y)
      for (int x = 0; x < d.image.width; ++x)
        for (int c = 0; c < 4; ++c) d.image.at(x, y, c) = page.at(e->x + x, e->y + y, c);
    data.push_back(std::move(d));
    records.push_back(*rec->second);
  }
  return {};
}

}  // namespace

Status JobManager::finalize(ActiveJob& job, JobRecord& record) {
  std::vector<RdmData> data = std::move(job.storage->rdms());
  std::vector<RdmRecord> records = job.records;
  AtlasLayout layout;
  if (job.mode == BakeMode::kFull) {
    layout = packCanonical(job.all);
  } else {
    std::set<std::tuple<int, int, int, int>> planned;
    for (const RdmId& id : job.plan) planned.insert({id.slot.x, id.slot.y, id.slot.z, id.level});
    std::vector<RdmId> copy;
    for (const RdmId& id : job.all) {
      if (!planned.count({id.slot.x, id.slot.y, id.slot.z, id.level})) copy.push_back(id);
    }
    AtlasLayout base_layout;
    if (Status s = copyFromBase(store_, record.base_job, copy, data, records, base_layout); !s)
      return s;
    layout = packIncremental(base_layout, job.all);
  }
  layout.scene_version = record.scene_version;
  if (Status s = writeAtlasOutputs(store_.outDir(job.id), layout, data); !s) return s;
  return store_.saveRdmRecords(job.id, records);
}

}  // namespace rdm::server
