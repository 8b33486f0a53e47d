#include "job_finisher.h"

#include <set>

#include "job_rdm_source.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/atlas/rdm_store.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/base/file_util.h"
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

Status JobFinisher::finalize(ActiveJob& job, const JobRecord& record,
                             const std::optional<JobRecord>& base,
                             const FaceLightProgressFn& on_face_light) {
  if (Status s = job.spill->status(); !s) return s;
  const std::string out = store_.outDir(job.id);
  if (Status s = makeDirectories(out); !s) return s;
  auto own = JobRdmSource::open(*job.spill, job.plan, nullptr, job.view, job.id);
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
  auto source = JobRdmSource::open(*job.spill, job.plan, &store_, job.view, job.id);
  if (!source) return source.status();
  if (Status s = writeAtlasOutputs(out, job.view.layout, **source); !s) return s;
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
