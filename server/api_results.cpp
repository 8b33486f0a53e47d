// Result routes: atlas.exr (?page=N; a bc6h job's atlas.ktx2 and depth.exr), index.json, index.txt,
// face_light.bin, delta?from=JOB and rdms/{i},{j},{k}/{level}.exr of a succeeded job (409 before),
// and delta.bin?from=JOB
// [&pass=N], which also answers from a running job's published passes. Every stored file is
// checked against its checksum before it is served or read (rdm/service/stored_file.h): a
// damaged one answers 500 `corrupt-data`, and the ETag of a result file is its XXH3 64.
#include <cstdio>
#include <map>
#include <tuple>

#include "api.h"
#include "http_util.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_json.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/atlas/rdm_store.h"
#include "rdm/bake/face_light.h"
#include "rdm/base/file_util.h"
#include "rdm/base/log.h"
#include "rdm/image/exr_io.h"
#include "rdm/service/resource_id.h"
#include "rdm/service/stored_file.h"

namespace rdm::server {
namespace {

using nlohmann::json;

std::variant<JobRecord, Problem> succeededJob(ApiContext& ctx, const std::string& id) {
  auto job = validId(id, 'j') ? ctx.jobs.get(id) : std::nullopt;
  if (!job) return notFound("no job '" + id + "'");
  if (job->state != JobState::kSucceeded) {
    return conflict("job " + id + " is " + stateName(job->state) +
                    ": its results do not exist (yet)");
  }
  ctx.jobs.noteFetched(id);  // retention spares a job clients read (--fetch-grace)
  return *job;
}

// The answer to a stored file that failed its check (already quarantined and logged).
Problem damaged(const std::string& job, const std::string& name, const Status& status) {
  if (status.code() != StatusCode::kCorrupt) {
    logEvent(LogLevel::kError, "request_error", {{"message", status.message()}});
    return internalError();
  }
  return corruptData("job " + job + ": its stored " + name +
                     " fails its checksum or is cut short; it is not served. Bake the job again");
}

// A result file of `job`, checked against the job's checksums.json.
std::variant<VerifiedFile, Problem> verifiedFile(ApiContext& ctx, const std::string& job,
                                                 const std::string& name) {
  auto file = readVerifiedResult(ctx.jobs.store().outDir(job), name);
  if (!file) return damaged(job, name, file.status());
  return std::move(*file);
}

std::variant<AtlasLayout, Problem> loadLayout(ApiContext& ctx, const std::string& id) {
  auto file = verifiedFile(ctx, id, "index.json");
  if (auto* p = std::get_if<Problem>(&file)) return *p;
  auto layout = parseIndexJson(std::get<VerifiedFile>(file).bytes);
  if (!layout) return internalError();
  return *layout;
}

// The file's bytes once they pass their check; its ETag is their XXH3 64 (`"<16 hex>"`).
std::optional<Problem> sendFile(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res, const std::string& job,
                                const std::string& name, const char* type) {
  auto file = verifiedFile(ctx, job, name);
  if (auto* p = std::get_if<Problem>(&file)) return *p;
  VerifiedFile& f = std::get<VerifiedFile>(file);
  if (handleEtag(req, res, "\"" + hashHex(f.hash) + "\"")) return std::nullopt;
  res.set_content(std::move(f.bytes), type);
  return std::nullopt;
}

std::optional<Problem> getArtifact(ApiContext& ctx, const httplib::Request& req,
                                   httplib::Response& res) {
  const std::string id = req.matches[1], file = req.matches[2];
  auto job = succeededJob(ctx, id);
  if (auto* p = std::get_if<Problem>(&job)) return *p;
  if (file == "index.json") return sendFile(ctx, req, res, id, file, "application/json");
  if (file == "index.txt") return sendFile(ctx, req, res, id, file, "text/plain");
  if (file == kFaceLightFile) {
    if (std::get<JobRecord>(job).face_light_spp <= 0)
      return notFound("job " + id + " was baked without face light (bake request key face_light)");
    return sendFile(ctx, req, res, id, file, "application/octet-stream");
  }
  if (file == "noise.exr" && std::get<JobRecord>(job).mode != BakeMode::kFull)
    return notFound("job " + id + " is incremental: only a full job has a noise map (its " +
                    "copied RDMs' errors are their own job's)");
  auto layout = loadLayout(ctx, id);
  if (auto* p = std::get_if<Problem>(&layout)) return *p;
  const bool bc6h = std::get<AtlasLayout>(layout).radiance == RadianceFormat::kBc6h;
  const bool bc6h_file = file == "atlas.ktx2" || file == "depth.exr";
  if (bc6h_file != bc6h && file != "noise.exr") {
    return notFound(bc6h ? "job " + id + " has a bc6h atlas: atlas.ktx2 and depth.exr"
                         : "job " + id +
                               " has no bc6h atlas (bake request key radiance): " + "atlas.exr");
  }
  const long long pages = (long long)std::get<AtlasLayout>(layout).pages.size();
  auto page = queryInt(req, "page", 0, std::max(0ll, pages - 1));
  if (auto* p = std::get_if<Problem>(&page)) return *p;
  if (pages == 0) return notFound("the atlas of job " + id + " is empty");
  const int n = int(std::get<std::optional<long long>>(page).value_or(0));
  res.set_header("X-Atlas-Pages", std::to_string(pages));
  if (file == "atlas.ktx2") return sendFile(ctx, req, res, id, atlasKtx2FileName(n), "image/ktx2");
  const std::string name = file == "noise.exr"   ? noisePageFileName(n)
                           : file == "depth.exr" ? atlasDepthFileName(n)
                                                 : atlasPageFileName(n);
  return sendFile(ctx, req, res, id, name, "image/x-exr");
}

// A job's result as a client may read it: a published pass of a running job (texels of its
// own RDMs in memory), or a succeeded job's files. Texels of RDMs baked by earlier jobs come
// from those jobs' per-RDM stores.
struct JobResult {
  JobRecord job;
  AtlasView view;
  int pass = 0;
  BakeSettings settings;
  std::shared_ptr<const PublishedPass> live;
};

std::variant<JobResult, Problem> filesResult(ApiContext& ctx, const JobRecord& job) {
  JobResult r;
  r.job = job, r.pass = job.passes_total - 1, r.settings = job.settings;
  auto layout = loadLayout(ctx, job.id);
  if (auto* p = std::get_if<Problem>(&layout)) return *p;
  r.view.layout = std::move(std::get<AtlasLayout>(layout));
  auto records = ctx.jobs.store().loadRdmRecords(job.id);  // sealed with an XXH3 64
  if (!records) {
    logEvent(LogLevel::kError, "request_error",
             {{"message",
               "job " + std::string(job.id) + ": rdms.bin is missing or fails its checksum"}});
    return corruptData("job " + job.id + ": its stored rdms.bin is missing or fails its " +
                       "checksum; it is not served. Bake the job again");
  }
  for (const RdmRecord& rec : *records) r.view.origin[rdmKey(rec.id)] = rec.origin_job;
  return r;
}

// `min_pass`: the pass the client waits for; a later one (or the files) also answers.
std::variant<JobResult, Problem> readableResult(ApiContext& ctx, const std::string& id,
                                                int min_pass) {
  auto job = validId(id, 'j') ? ctx.jobs.get(id) : std::nullopt;
  if (!job) return notFound("no job '" + id + "'");
  if (job->state == JobState::kSucceeded) {
    ctx.jobs.noteFetched(id);
    return filesResult(ctx, *job);
  }
  auto live = ctx.jobs.published(id);
  if (job->state != JobState::kRunning || !live || live->pass < min_pass) {
    return conflict("job " + id + " is " + stateName(job->state) + ": pass " +
                    std::to_string(min_pass) + " is not done (yet); poll the job");
  }
  JobResult r;
  r.job = *job, r.view = live->view, r.pass = live->pass, r.settings = live->settings;
  r.live = live;
  return r;
}

class TexelSource {
 public:
  TexelSource(ApiContext& ctx, const JobResult& result) : ctx_(ctx), result_(result) {}
  Expected<Image> read(const RdmKey& key) {
    auto origin = result_.view.origin.find(key);
    if (origin == result_.view.origin.end()) return Status::error("RDM without an origin");
    if (result_.live && origin->second == result_.job.id) return result_.live->ownImage(key);
    auto it = readers_.find(origin->second);
    if (it == readers_.end()) {
      auto reader =
          RdmStoreReader::open(ctx_.jobs.store().outDir(origin->second) + "/" + kRdmStoreFile);
      if (!reader) return reader.status();
      it = readers_.emplace(origin->second, std::move(*reader)).first;
    }
    return it->second.read(key);
  }

 private:
  ApiContext& ctx_;
  const JobResult& result_;
  std::map<std::string, RdmStoreReader> readers_;
};

// The `from` job a delta starts at: a job of the same scene with the same pages whose final
// pass is published (its files may still be being written) or that succeeded.
std::variant<JobResult, Problem> deltaBase(ApiContext& ctx, const httplib::Request& req,
                                           const JobResult& now) {
  if (!req.has_param("from"))
    return badRequest("query parameter 'from' (a job id) is required", "from");
  const std::string from = req.get_param_value("from");
  auto record = validId(from, 'j') ? ctx.jobs.get(from) : std::nullopt;
  if (!record) return notFound("no job '" + from + "'");
  auto old = readableResult(ctx, from, record->passes_total - 1);
  if (auto* p = std::get_if<Problem>(&old)) return *p;
  const std::string full = "fetch /v1/jobs/" + now.job.id + "/index.json and its atlas pages";
  if (record->scene_id != now.job.scene_id)
    return conflict("job " + from + " belongs to another scene: " + full, "from");
  if (!pagesGrow(std::get<JobResult>(old).view.layout, now.view.layout))
    return conflict("the atlas pages of job " + now.job.id + " are not those of job " + from +
                        " or grown from them, so no delta chains them: " + full,
                    "from");
  return old;
}

// GET delta?from=JOB: the listing only (JSON), for a succeeded job.
std::optional<Problem> getDelta(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res) {
  const std::string id = req.matches[1];
  auto job = succeededJob(ctx, id);
  if (auto* p = std::get_if<Problem>(&job)) return *p;
  auto now = filesResult(ctx, std::get<JobRecord>(job));
  if (auto* p = std::get_if<Problem>(&now)) return *p;
  auto old = deltaBase(ctx, req, std::get<JobResult>(now));
  if (auto* p = std::get_if<Problem>(&old)) return *p;
  const AtlasView& old_view = std::get<JobResult>(old).view;
  const DeltaSelection sel = selectDelta(old_view, std::get<JobResult>(now).view);
  json added = json::array(), changed = json::array(), removed = json::array();
  for (const AtlasEntry& e : sel.rects)
    (old_view.layout.find(e.id.slot, e.id.level) ? changed : added).push_back(atlasEntryJson(e));
  for (const AtlasEntry& e : sel.removed) removed.push_back(atlasEntryJson(e));
  json pages = json::array();
  for (const AtlasPage& p : std::get<JobResult>(now).view.layout.pages)
    pages.push_back({{"width", p.width}, {"height", p.height}});
  sendJson(res, {{"job", id},
                 {"from", req.get_param_value("from")},
                 {"pages", pages},
                 {"added", added},
                 {"changed", changed},
                 {"removed", removed}});
  return std::nullopt;
}

// GET delta.bin?from=JOB[&pass=N]: every changed rect of the pass, with texels, in one
// message (rdm/atlas/atlas_delta.h).
std::optional<Problem> getDeltaBin(ApiContext& ctx, const httplib::Request& req,
                                   httplib::Response& res) {
  const std::string id = req.matches[1];
  auto pass = queryInt(req, "pass", 0, 15);
  if (auto* p = std::get_if<Problem>(&pass)) return *p;
  auto now = readableResult(ctx, id, int(std::get<std::optional<long long>>(pass).value_or(0)));
  if (auto* p = std::get_if<Problem>(&now)) return *p;
  const JobResult& result = std::get<JobResult>(now);
  auto old = deltaBase(ctx, req, result);
  if (auto* p = std::get_if<Problem>(&old)) return *p;
  const DeltaSelection sel = selectDelta(std::get<JobResult>(old).view, result.view);
  AtlasDelta delta;
  delta.job = id, delta.from = req.get_param_value("from");
  delta.pass = result.pass, delta.passes = result.job.passes_total;
  delta.final = result.pass == result.job.passes_total - 1;
  delta.settings = result.settings, delta.layout = result.view.layout;
  delta.removed = sel.removed;
  TexelSource source(ctx, result);
  for (const AtlasEntry& e : sel.rects) {
    auto texels = source.read(rdmKey(e.id));
    if (!texels && texels.status().code() == StatusCode::kCorrupt)
      return damaged(id, "per-RDM store (" + std::string(kRdmStoreFile) + ")", texels.status());
    if (!texels) {
      logEvent(LogLevel::kError, "request_error",
               {{"message", "delta of job " + std::string(id) + ": " + texels.error()}});
      return conflict("job " + id + ": the texels of an RDM are not stored (a job from before " +
                      "per-RDM stores?); fetch the atlas pages instead");
    }
    delta.rects.push_back({e, std::move(*texels)});
  }
  res.set_header("X-Delta-Pass", std::to_string(delta.pass));
  res.set_content(encodeAtlasDelta(delta), kAtlasDeltaMediaType);
  return std::nullopt;
}

std::optional<Problem> getRdm(ApiContext& ctx, const httplib::Request& req,
                              httplib::Response& res) {
  const std::string id = req.matches[1];
  auto job = succeededJob(ctx, id);
  if (auto* p = std::get_if<Problem>(&job)) return *p;
  int v[4];
  for (int i = 0; i < 4; ++i) {
    const std::string s = req.matches[size_t(i) + 2];
    if (s.size() > 4) return notFound("no such RDM");
    v[i] = std::stoi(s);
  }
  auto result = filesResult(ctx, std::get<JobRecord>(job));
  if (auto* p = std::get_if<Problem>(&result)) return *p;
  const AtlasEntry* e = std::get<JobResult>(result).view.layout.find({v[0], v[1], v[2]}, v[3]);
  if (!e)
    return notFound("job " + id + " has no RDM at slot (" + std::to_string(v[0]) + "," +
                    std::to_string(v[1]) + "," + std::to_string(v[2]) + ") level " +
                    std::to_string(v[3]));
  const std::string name = "rdm-" + std::to_string(v[0]) + "-" + std::to_string(v[1]) + "-" +
                           std::to_string(v[2]) + "-" + std::to_string(v[3]);
  TexelSource source(ctx, std::get<JobResult>(result));
  auto img = source.read(rdmKey(e->id));
  if (!img && img.status().code() == StatusCode::kCorrupt)
    return damaged(id, "RDM " + name + " (" + kRdmStoreFile + ")", img.status());
  if (!img) return conflict("job " + id + ": this RDM's texels are not stored; fetch the atlas");
  auto bytes = encodeExr(*img, kRgbzChannels);
  if (!bytes) return internalError();
  // Read from the store (checked per RDM), so the ETag is the checked content's hash.
  if (handleEtag(req, res, bodyEtag(*bytes))) return std::nullopt;
  res.set_content(std::move(*bytes), "image/x-exr");
  return std::nullopt;
}

}  // namespace

void registerResultRoutes(httplib::Server& server, ApiContext& ctx) {
  ApiContext* c = &ctx;
  server.Get(
      R"(/v1/jobs/([^/]+)/(atlas\.exr|atlas\.ktx2|depth\.exr|noise\.exr|index\.json|index\.txt|face_light\.bin))",
      wrap([c](const auto& req, auto& res) { return getArtifact(*c, req, res); }));
  server.Get(R"(/v1/jobs/([^/]+)/delta\.bin)",
             wrap([c](const auto& req, auto& res) { return getDeltaBin(*c, req, res); }));
  server.Get(R"(/v1/jobs/([^/]+)/delta)",
             wrap([c](const auto& req, auto& res) { return getDelta(*c, req, res); }));
  server.Get(R"(/v1/jobs/([^/]+)/rdms/(\d+),(\d+),(\d+)/(\d+)\.exr)",
             wrap([c](const auto& req, auto& res) { return getRdm(*c, req, res); }));
}

}  // namespace rdm::server
