#include "rdm/atlas/incremental_baker.h"

#include "rdm/atlas/atlas_incremental.h"
#include "rdm/atlas/slot_sets_file.h"
#include "rdm/bake/preview_pass.h"
#include "rdm/scene/scene_diff.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

struct Plan {
  std::vector<RdmId> all, rebake;
  AtlasLayout layout;
  bool whole = true;
};

std::vector<RdmRecord> recordList(const std::map<RdmKey, RdmRecord>& records) {
  std::vector<RdmRecord> out;
  for (const auto& [key, r] : records) out.push_back(r);
  return out;
}

// The slot sets of `dir`, refused unless every RDM of `layout` has them.
Expected<std::map<RdmKey, RdmRecord>> recordsOf(const std::string& dir, const AtlasLayout& layout) {
  auto records = readSlotSetsFile(dir);
  if (!records) return records.status();
  for (const AtlasEntry& e : layout.entries) {
    if (records->count(rdmKey(e.id))) continue;
    const glm::ivec3 s = e.id.slot;
    return Status::invalid(kRdmRecordsFile, dir + "/" + kRdmRecordsFile +
                                                " has no slot sets for the RDM at slot " +
                                                std::to_string(s.x) + "," + std::to_string(s.y) +
                                                "," + std::to_string(s.z));
  }
  return records;
}

}  // namespace

Status IncrementalBaker::seedFromAtlas(const Scene& scene, const std::string& dir) {
  auto world = std::make_unique<VoxelWorld>(buildWorld(scene));
  auto atlas = readAtlasOutputs(dir);
  if (!atlas) return atlas.status();
  if (Status s = checkLayoutMatches(atlas->layout, listRdms(*world, scene.bake)); !s)
    return Status::invalid("atlas", dir + " holds other RDMs than the scene: " + s.message());
  if (atlas->layout.lighting != lightingFingerprint(scene, scene.bake))
    return Status::invalid("lighting", dir +
                                           " was not baked with the scene's lighting and bake "
                                           "settings (index.json \"lighting\")");
  auto records = recordsOf(dir, atlas->layout);
  if (!records) return records.status();
  std::map<RdmKey, Image> images;
  for (AtlasEntry& e : atlas->layout.entries) {
    images[rdmKey(e.id)] = rdmTexels(*atlas, e);
    for (FaceTile& t : e.faces) t.exponent = 0;  // the texels are radiance, as a bake's
  }
  atlas->layout.radiance = RadianceFormat::kFloat32, atlas->layout.lighting.clear();
  scene_ = scene, world_ = std::move(world), layout_ = std::move(atlas->layout);
  images_ = std::move(images), records_ = std::move(*records);
  return {};
}

AtlasDelta IncrementalBaker::deltaOf(const AtlasLayout& layout, const std::vector<RdmId>& ids,
                                     const std::map<RdmKey, Image>& images) const {
  AtlasDelta d;
  d.job = "local-" + std::to_string(bakes_);
  d.from = bakes_ > 1 ? "local-" + std::to_string(bakes_ - 1) : "";
  d.layout = layout;
  for (const RdmId& id : ids) {
    const AtlasEntry* e = layout.find(id.slot, id.level);
    auto it = images.find(rdmKey(id));
    if (e && it != images.end()) d.rects.push_back({*e, it->second});
  }
  return d;
}

Status IncrementalBaker::bake(const Scene& scene, const IncrementalBakeOptions& options,
                              const std::function<void(AtlasDelta)>& on_pass) {
  auto world = std::make_unique<VoxelWorld>(buildWorld(scene));
  Plan plan;
  plan.all = listRdms(*world, scene.bake);
  if (!scene_ || options.mode == BakeMode::kFull) {
    plan.rebake = plan.all;
    plan.layout = packCanonical(plan.all, storedFacesOf(*world));
  } else {
    SceneDiff diff = diffScenes(*scene_, scene);
    if (!(scene_->bake == scene.bake)) diff.dirty_all = true;
    const std::vector<RdmRecord> base = recordList(records_);
    RebakeSelection sel =
        selectRebake(options.mode, diff, emittersDiffer(*world_, *world), *world, plan.all, base);
    plan.rebake = std::move(sel.rebake);
    orderByVisibility(plan.rebake, diff, *world, base);
    plan.layout = packIncremental(layout_, plan.all, storedFacesOf(*world));
    plan.whole = !pagesGrow(layout_, plan.layout);
  }
  ++bakes_;
  const std::vector<BakeSettings> passes =
      plan.whole ? std::vector<BakeSettings>{scene.bake} : progressivePasses(scene.bake);
  std::map<RdmKey, Image> images = images_;
  std::vector<RdmData> baked;
  for (size_t p = 0; p < passes.size(); ++p) {
    BakeOptions bake_options;
    bake_options.threads = options.threads;
    bake_options.cancel = options.cancel;
    bake_options.record_slot_sets = p + 1 == passes.size();
    if (options.on_progress)
      bake_options.on_progress = [&](const BakeProgress& pr) {
        options.on_progress(int(p), int(passes.size()), pr);
      };
    BakeResult result =
        bakeRdms(*world, passes[p], atPassSizes(plan.rebake, passes[p]), bake_options);
    if (result.report.cancelled) {
      if (p > 0) {  // preview rects are on screen: put the last atlas back
        AtlasDelta restore = deltaOf(layout_, plan.rebake, images_);
        restore.final = true;
        on_pass(std::move(restore));
      }
      --bakes_;
      return Status::error(StatusCode::kCancelled, "bake cancelled");
    }
    for (const RdmData& d : result.rdms) {
      const int size = shared::hemisphereSize(d.id.level, scene.bake.max_hemisphere);
      images[rdmKey(d.id)] = expandRdmImage(d.image, size);
    }
    AtlasDelta delta = deltaOf(plan.layout, plan.whole ? plan.all : plan.rebake, images);
    delta.pass = int(p), delta.passes = int(passes.size());
    delta.final = p + 1 == passes.size();
    delta.settings = passes[p];
    on_pass(std::move(delta));
    if (p + 1 == passes.size()) baked = std::move(result.rdms);
  }
  std::map<RdmKey, RdmRecord> records;
  for (const RdmId& id : plan.all) {
    auto it = records_.find(rdmKey(id));
    if (it != records_.end()) records[rdmKey(id)] = it->second;
  }
  for (RdmData& d : baked) records[rdmKey(d.id)] = recordOf(d, "local");
  for (auto it = images.begin(); it != images.end();)
    it = plan.layout.find({std::get<0>(it->first), std::get<1>(it->first), std::get<2>(it->first)},
                          std::get<3>(it->first))
             ? std::next(it)
             : images.erase(it);
  scene_ = scene, world_ = std::move(world), layout_ = plan.layout;
  images_ = std::move(images), records_ = std::move(records);
  return {};
}

}  // namespace rdm
