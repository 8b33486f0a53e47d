// JobManager::prepare: turning a job record into scheduled work units (and a preview pass for
// progressive jobs), finished units restored from the unit log. JobFinisher turns them into
// the job's results.
#include <algorithm>
#include <chrono>
#include <map>
#include <thread>
#include <tuple>

#include "active_job.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_incremental.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/preview_pass.h"
#include "rdm/base/failpoint.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/service/job_manager.h"
#include "rdm/service/stored_file.h"

namespace rdm {
namespace {

struct Selection {
  std::vector<RdmId> plan;
  int changed_slots = 0;
  bool dirty_all = false;
};

std::variant<Selection, std::string> selectPlan(const JobRecord& job, const std::vector<RdmId>& all,
                                                const VoxelWorld& world, SceneStore& scenes,
                                                const std::vector<RdmRecord>& base_records,
                                                const JobRecord& base) {
  auto base_scene = scenes.get(job.scene_id, base.scene_version);
  auto target_scene = scenes.get(job.scene_id, job.scene_version);
  if (!base_scene || !target_scene) return std::string("scene version missing");
  SceneDiff diff = diffScenes(*base_scene, *target_scene);
  if (!(base.settings == job.settings))
    diff.dirty_all = true, diff.global_changes.push_back("settings");
  const VoxelWorld base_world = buildWorld(*base_scene);
  const bool emitters = emittersDiffer(base_world, world);
  // The kernel is compiled per effect set (sun, emitters): another variant may round
  // differently, so on Vulkan a change of the set re-bakes everything.
  const EffectSet was = sceneEffects(base_world), is = sceneEffects(world);
  if (job.backend == "vulkan" && (was.sun != is.sun || was.emitters != is.emitters))
    diff.dirty_all = true, diff.global_changes.push_back("effects (Vulkan kernel variant)");
  RebakeSelection sel = selectRebake(job.mode, diff, emitters, world, all, base_records);
  orderByVisibility(sel.rebake, diff, world, base_records);
  return Selection{sel.rebake, int(diff.changed_slots.size()), diff.dirty_all};
}

std::vector<int> localIndices(const std::vector<BakeUnit>& units, size_t rdm_count) {
  std::vector<int> next(rdm_count, 0), local;
  for (const BakeUnit& u : units) local.push_back(next[size_t(u.rdm)]++);
  return local;
}

// A full job bakes slot by slot: a slot's RDMs of every level share its radiance maps, which
// the session keeps until their last user ran, and finish together.
std::vector<RdmId> bySlot(std::vector<RdmId> rdms, const VoxelWorld& world) {
  std::stable_sort(rdms.begin(), rdms.end(), [&](const RdmId& a, const RdmId& b) {
    return world.slotLinear(a.slot) < world.slotLinear(b.slot);
  });
  return rdms;
}

// Restores finished units from the unit log, one unit at a time; an RDM whose units are all
// restored goes to the spill at once. Returns how many units were restored.
uint64_t restoreUnits(ActiveJob& job, const JobStore& store, JobRecord& record) {
  std::map<std::tuple<int, int, int, int>, size_t> by_key;
  for (size_t i = 0; i < job.units.size(); ++i) {
    const BakeUnit& u = job.units[i];
    by_key[{u.rdm, u.face, u.x0, u.y0}] = i;
  }
  uint64_t restored = 0;
  store.forEachUnit(job.id, [&](UnitResult& r) {
    if (job.abort) return;  // the caller checks it after
    auto it = by_key.find({r.unit.rdm, r.unit.face, r.unit.x0, r.unit.y0});
    if (it == by_key.end() || job.unit_state[it->second] != 0) return;
    const BakeUnit& u = job.units[it->second];
    if (u.x1 != r.unit.x1 || u.y1 != r.unit.y1 || !(job.plan[size_t(u.rdm)] == r.id)) return;
    if (!applyUnit(r, job.storage->rdmTexels(size_t(u.rdm)))) return;
    job.unit_state[it->second] = 2;
    RdmRecord& rec = job.records[size_t(u.rdm)];
    rec.full_set.unite(r.full_set);
    rec.first_set.unite(r.first_set);
    rec.smooth = rec.smooth || r.smooth;
    record.texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
    record.rays += r.rays;
    record.bake_seconds += r.seconds;
    ++restored;
    if (--job.units_left[size_t(u.rdm)] == 0) job.releaseFinished(size_t(u.rdm));
  });
  while (job.cursor < job.units.size() && job.unit_state[job.cursor] != 0) ++job.cursor;
  return restored;
}

// The result's layout and the origin of each RDM: this job for the plan, the base's origin
// for copied RDMs. Incremental layouts keep the base's tiles (packIncremental).
std::variant<AtlasView, std::string> resultView(const JobRecord& record, const ActiveJob& job,
                                                const JobStore& store,
                                                const std::vector<RdmRecord>& base_records) {
  AtlasView view;
  if (record.mode == BakeMode::kFull) {
    view.layout = packCanonical(job.all, storedFacesOf(*job.world), record.radiance);
  } else {
    // Checked against the base's manifest: a damaged layout is never built upon.
    auto index = readVerifiedResult(store.outDir(record.base_job), "index.json");
    if (!index) return "base job " + record.base_job + ": " + index.error();
    auto base_layout = parseIndexJson(index->bytes);
    if (!base_layout) return "base job " + record.base_job + ": " + base_layout.error();
    view.layout =
        packIncremental(*base_layout, job.all, storedFacesOf(*job.world), record.radiance);
    for (const RdmRecord& r : base_records) view.origin[rdmKey(r.id)] = r.origin_job;
  }
  view.layout.scene_version = record.scene_version;
  view.layout.radiance = record.radiance;
  view.layout.lighting = lightingFingerprint(*job.scene, record.settings);
  for (const RdmId& id : job.plan) view.origin[rdmKey(id)] = record.id;
  return view;
}

std::optional<PreviewPass> makePreview(const ActiveJob& job) {
  const std::vector<BakeSettings> passes = progressivePasses(job.settings);
  if (job.mode == BakeMode::kFull || passes.size() < 2 || job.plan.empty()) return std::nullopt;
  PreviewPass p;
  p.settings = passes.front();
  BakeOptions options;
  options.threads = 1;
  p.session = std::make_unique<BakeSession>(*job.world, p.settings,
                                            atPassSizes(job.plan, p.settings), options);
  p.units = p.session->units();
  p.left = p.units.size();
  return p;
}

}  // namespace

std::map<RdmKey, Image> snapshotImages(BakeSession& session) {
  std::map<RdmKey, Image> out;
  for (const RdmData& r : session.rdms()) out[rdmKey(r.id)] = r.image;
  return out;
}

Status JobManager::prepare(const JobRecord& record, ActiveJob& into) {
  ActiveJob* job = &into;
  // id and mode were set under the lock before this thread started (nextToPrepare reads them).
  job->seq = record.seq, job->settings = record.settings;
  const Status aborted =
      Status::error(StatusCode::kCancelled, "job " + record.id + ": preparing stopped");
  job->vulkan = record.backend == "vulkan";
  if (job->vulkan && (!vulkan_ || vulkan_->device().name != record.device)) {
    return Status::error(
        StatusCode::kConflict,
        "the job bakes on the Vulkan device '" + record.device + "', and this server " +
            (vulkan_ ? "bakes on '" + vulkan_->device().name + "'" : std::string("has no Vulkan")) +
            " (rdm serve --backend, --device); submit it again",
        "device");
  }
  job->scene = scenes_.get(record.scene_id, record.scene_version);
  if (!job->scene) return Status::error("scene " + record.scene_id + " version missing");
  job->world = std::make_unique<VoxelWorld>(buildWorld(*job->scene));
  hitFailpoint(Failpoint::kPrepareAlloc);
  hitFailpoint(Failpoint::kPrepareAbort);
  if (takeFailpoint(Failpoint::kPrepareSlow)) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!job->abort && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (job->abort) return aborted;
  job->all = listRdms(*job->world, job->settings);
  if (job->abort) return aborted;
  JobRecord update = record;
  update.rays = 0, update.texels_done = 0, update.bake_seconds = 0.0;
  std::vector<RdmRecord> base_records;
  if (record.mode != BakeMode::kFull) {
    auto loaded = store_.loadRdmRecords(record.base_job);
    if (!loaded)
      return Status::error("base job " + record.base_job + ": rdms.bin missing or corrupt");
    base_records = std::move(*loaded);
  }
  if (auto plan = store_.loadPlan(record.id)) {  // resuming: the plan is fixed
    job->plan = std::move(*plan);
  } else if (record.mode == BakeMode::kFull) {
    job->plan = bySlot(job->all, *job->world);
  } else {
    std::optional<JobRecord> base = get(record.base_job);
    if (!base) return Status::error("base job " + record.base_job + " unknown");
    auto sel = selectPlan(record, job->all, *job->world, scenes_, base_records, *base);
    if (auto* e = std::get_if<std::string>(&sel)) return Status::error(*e);
    Selection& s = std::get<Selection>(sel);
    job->plan = std::move(s.plan);
    update.changed_slots = s.changed_slots, update.dirty_all = s.dirty_all;
  }
  if (job->abort) return aborted;
  auto view = resultView(record, *job, store_, base_records);
  if (auto* e = std::get_if<std::string>(&view)) return Status::error(*e);
  job->view = std::move(std::get<AtlasView>(view));
  if (Status s = store_.savePlan(record.id, job->plan); !s) return s;
  auto spill = RdmSpill::create(store_.jobDir(record.id));
  if (!spill) return spill.status();
  job->spill = std::move(*spill);
  BakeOptions options;
  options.threads = 1;
  options.record_slot_sets = true;
  options.on_rdm_done = [spill = job->spill.get()](const RdmData& d) { spill->append(d); };
  job->storage = std::make_unique<BakeSession>(*job->world, job->settings, job->plan, options);
  job->units = job->storage->units();
  job->local_index = localIndices(job->units, job->plan.size());
  job->unit_state.assign(job->units.size(), 0);
  job->units_left.assign(job->plan.size(), 0);
  for (const BakeUnit& u : job->units) job->units_left[size_t(u.rdm)]++;
  job->records.resize(job->plan.size());
  for (size_t r = 0; r < job->plan.size(); ++r)
    job->records[r].id = job->plan[r], job->records[r].origin_job = record.id;
  for (size_t r = 0; r < job->plan.size() && !job->abort; ++r)
    if (job->units_left[r] == 0) job->releaseFinished(r);  // every face skipped
  if (job->abort) return aborted;
  update.units_restored = restoreUnits(*job, store_, update);
  if (job->abort) return aborted;
  update.units_done = update.units_restored;
  if (update.units_restored == 0) job->preview = makePreview(*job);
  update.passes_total = job->passes();
  update.passes_done = 0;
  update.pass_seconds.clear();
  update.preview_spp = job->preview ? job->preview->settings.spp : 0;
  update.rdms_scene = int(job->all.size());
  update.rdms_rebake = int(job->plan.size());
  update.rdms_copied = int(job->all.size() - job->plan.size());
  update.units_total = job->units.size();
  update.texels_total = 0;
  for (const BakeUnit& u : job->units)
    update.texels_total += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  const bool bakes_face_light = record.face_light_spp > 0 && record.mode == BakeMode::kFull;
  update.face_light_faces_total = bakes_face_light ? exposedFaceCount(*job->world) : 0;
  update.face_light_faces_done = 0;
  EffectSet effects = sceneEffects(*job->world);
  update.effects_simulated = effects.describeSimulated();
  update.effects_skipped = effects.describeSkipped();
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord& live = records_.at(record.id);
  const bool cancel = live.cancel_requested;
  live = update;
  live.cancel_requested = cancel;
  job->cancelled = cancel;
  job->cancel_flag = cancel;
  return {};
}

}  // namespace rdm
