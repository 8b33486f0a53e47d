#include "job_finisher.h"

#include <chrono>
#include <set>

#include "job_rdm_source.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_json.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/atlas/rdm_store.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/bake/denoise.h"
#include "rdm/base/file_util.h"
#include "rdm/base/log.h"
#include "rdm/image/ktx2.h"
#include "rdm/service/stored_file.h"

namespace rdm {

Status abortedStatus(const ActiveJob& job, const char* step) {
  return Status::error(StatusCode::kCancelled,
                       "job " + job.id + ": " + step + " stopped (cancelled or the daemon stops)");
}

// The relative errors of the RDMs the job baked (bake_report.json's noise figures) and, for
// a full job, whose RDMs all carry their standard error, the noise map.
Status measureNoise(ActiveJob& job, const RdmSource& own, const std::string& out) {
  std::vector<RdmErrorStats> stats(own.ids().size());
  for (size_t i = 0; i < stats.size(); ++i) {
    if (Status s = own.visit(i, [&](const RdmData& rdm) { stats[i] = rdmErrorStats(rdm); }); !s)
      return s;
  }
  summariseBake(stats, job.noise);
  if (job.mode != BakeMode::kFull) return {};
  return writeNoiseMaps(out, job.view.layout, own);
}

namespace {

// An incremental bc6h job's atlas copies the blocks of the tiles it keeps from its base job's
// (a bc6h job too, its files checked against their checksums); none for any other job.
Expected<std::optional<Bc6hReuse>> bc6hReuseOf(const ActiveJob& job, const JobRecord& record,
                                               const JobStore& store) {
  if (job.mode == BakeMode::kFull || record.radiance != RadianceFormat::kBc6h)
    return std::optional<Bc6hReuse>();
  const std::string base_dir = store.outDir(record.base_job);
  auto index = readVerifiedResult(base_dir, "index.json");
  if (!index) return index.status();
  auto base = parseIndexJson(index->bytes);
  if (!base) return base.status();
  if (base->radiance != RadianceFormat::kBc6h) return std::optional<Bc6hReuse>();
  auto planned = std::make_shared<std::set<RdmKey>>();
  for (const RdmId& id : job.plan) planned->insert(rdmKey(id));
  Bc6hReuse reuse;
  reuse.base = std::move(*base);
  reuse.base_page = [base_dir](int page) -> Expected<Bc6hImage> {
    auto file = readVerifiedResult(base_dir, atlasKtx2FileName(page));
    if (!file) return file.status();
    auto ktx2 = decodeKtx2(file->bytes);
    if (!ktx2) return ktx2.status();
    return Bc6hImage{ktx2->width, ktx2->height, std::move(ktx2->data)};
  };
  reuse.rebaked = [planned](const RdmId& id) { return planned->count(rdmKey(id)) > 0; };
  return std::optional<Bc6hReuse>(std::move(reuse));
}

// The job's own RDMs filtered by the denoiser into a second spill in its directory, each with
// the others as neighbours. The RDMs it copies from earlier jobs' stores carry no standard
// error and so could take no part (denoise.h): they are not read.
Expected<std::shared_ptr<const RdmSpill>> denoiseOwn(ActiveJob& job, const JobStore& store,
                                                     int threads, DenoiseDevice* device) {
  const auto start = std::chrono::steady_clock::now();
  auto own = JobRdmSource::open(*job.spill, job.plan, nullptr, job.view, job.id);
  if (!own) return own.status();
  auto spill = RdmSpill::create(store.jobDir(job.id));
  if (!spill) return spill.status();
  DenoiseSettings settings;
  settings.prefiltered = job.settings.estimator == Estimator::kPrefiltered;
  DenoiseStats stats;
  if (Status s = denoiseRdms(**own, nullptr, **spill, settings, threads, stats, device); !s)
    return s;
  job.denoise_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  logEvent(LogLevel::kInfo, "denoise",
           {{"job", job.id},
            {"rdms", stats.rdms},
            {"texels_filtered", stats.filtered},
            {"seconds", job.denoise_seconds},
            {"cpu_seconds", stats.cpu_seconds},
            {"on", device ? "vulkan" : "cpu"},
            {"relative_error_before", stats.relativeErrorBefore()},
            {"relative_error_after", stats.relativeErrorAfter()}});
  return std::shared_ptr<const RdmSpill>(std::move(*spill));
}

}  // namespace

Status JobFinisher::finalize(ActiveJob& job, const JobRecord& record,
                             const std::optional<JobRecord>& base,
                             const FaceLightProgressFn& on_face_light) {
  if (Status s = job.spill->status(); !s) return s;
  const std::string out = store_.outDir(job.id);
  if (Status s = makeDirectories(out); !s) return s;
  std::shared_ptr<const RdmSpill> baked = job.spill;  // the RDMs the job writes
  if (record.denoise) {
    const std::unique_ptr<DenoiseDevice> device = denoiserFor(record);
    auto filtered = denoiseOwn(job, store_, threads_, device.get());
    if (!filtered) return filtered.status();
    baked = std::move(*filtered);
    if (job.abort) return abortedStatus(job, "denoising");
  }
  auto own = JobRdmSource::open(*baked, job.plan, nullptr, job.view, job.id);
  if (!own) return own.status();
  if (Status s = writeRdmStore(out + "/" + kRdmStoreFile, **own); !s) return s;
  if (job.abort) return abortedStatus(job, "writing the results");
  std::vector<RdmRecord> records = std::move(job.records);
  if (job.mode != BakeMode::kFull) {
    auto base_records = store_.loadRdmRecords(record.base_job);
    if (!base_records) return Status::error("base job " + record.base_job + ": rdms.bin missing");
    std::set<RdmKey> planned;
    for (const RdmId& id : job.plan) planned.insert(rdmKey(id));
    for (RdmRecord& r : *base_records) {
      if (!planned.count(rdmKey(r.id)) && job.view.layout.find(r.id.slot, r.id.level))
        records.push_back(std::move(r));
    }
  }
  auto source = JobRdmSource::open(*baked, job.plan, &store_, job.view, job.id);
  if (!source) return source.status();
  auto reuse = bc6hReuseOf(job, record, store_);
  if (!reuse) return reuse.status();
  Bc6hReuse* reusing = *reuse ? &**reuse : nullptr;
  const Bc6hEncodeFn encoder = bc6hEncoderFor(record);
  if (Status s = writeAtlasOutputs(out, job.view.layout, **source, encoder, reusing); !s) return s;
  if (record.radiance == RadianceFormat::kBc6h) {
    nlohmann::json fields = {{"job", job.id}, {"on", encoder ? "vulkan" : "cpu"}};
    if (reusing)
      fields.update({{"encoded", reusing->encoded_blocks}, {"reused", reusing->reused_blocks}});
    logEvent(LogLevel::kInfo, "bc6h_blocks", fields);
  }
  if (job.abort) return abortedStatus(job, "writing the results");
  if (Status s = measureNoise(job, **own, out); !s) return s;
  if (Status s = writeJobFaceLight(job, record, base, on_face_light); !s) return s;
  if (Status s = store_.saveRdmRecords(job.id, records); !s) return s;
  return writeResultChecksums(out);  // last: it lists every result file written above
}

std::shared_ptr<PublishedPass> makePublishedPass(const ActiveJob& job, int pass,
                                                 const BakeSettings& settings,
                                                 std::map<RdmKey, Image> own,
                                                 std::shared_ptr<const RdmSpill> spill) {
  auto p = std::make_shared<PublishedPass>();
  p->pass = pass, p->passes = job.passes(), p->settings = settings;
  p->view = job.view;
  p->own = std::move(own);
  if (spill) {
    const std::vector<RdmId> ids = spill->ids();
    for (size_t i = 0; i < ids.size(); ++i) p->spill_index[rdmKey(ids[i])] = i;
    p->spill = std::move(spill);
  }
  return p;
}

Expected<Image> PublishedPass::ownImage(const RdmKey& key) const {
  if (!spill) {
    auto it = own.find(key);
    if (it == own.end()) return Status::notFound("RDM not in the published pass");
    return it->second;
  }
  auto it = spill_index.find(key);
  if (it == spill_index.end()) return Status::notFound("RDM not in the published pass");
  Image image;
  const Status read = spill->visit(it->second, [&](const RdmData& d) { image = d.image; });
  if (!read) return read;
  return image;
}

}  // namespace rdm
