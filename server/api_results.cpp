// Result routes of a succeeded job: atlas.exr (?page=N), index.json, index.txt,
// delta?from=JOB and rdms/{i},{j},{k}/{level}.exr. 409 until the job has succeeded.
#include <map>
#include <tuple>

#include "api.h"
#include "http_util.h"
#include "ids.h"
#include "rdm/atlas.h"
#include "rdm/exr_io.h"
#include "rdm/file_util.h"

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
  return *job;
}

std::variant<AtlasLayout, Problem> loadLayout(ApiContext& ctx, const std::string& id) {
  auto text = readFileToString(ctx.jobs.store().outDir(id) + "/index.json");
  if (!text) return internalError();
  auto layout = parseIndexJson(*text);
  if (!layout) return internalError();
  return *layout;
}

std::optional<Problem> sendFile(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res, const std::string& job,
                                const std::string& name, const char* type) {
  if (handleEtag(req, res, "\"" + job + "/" + name + "\"")) return std::nullopt;
  auto bytes = readFileToString(ctx.jobs.store().outDir(job) + "/" + name);
  if (!bytes) return internalError();
  res.set_content(std::move(*bytes), type);
  return std::nullopt;
}

std::optional<Problem> getArtifact(ApiContext& ctx, const httplib::Request& req,
                                   httplib::Response& res) {
  const std::string id = req.matches[1], file = req.matches[2];
  auto job = succeededJob(ctx, id);
  if (auto* p = std::get_if<Problem>(&job)) return *p;
  if (file == "index.json") return sendFile(ctx, req, res, id, file, "application/json");
  if (file == "index.txt") return sendFile(ctx, req, res, id, file, "text/plain");
  auto layout = loadLayout(ctx, id);
  if (auto* p = std::get_if<Problem>(&layout)) return *p;
  const long long pages = (long long)std::get<AtlasLayout>(layout).pages.size();
  auto page = queryInt(req, "page", 0, std::max(0ll, pages - 1));
  if (auto* p = std::get_if<Problem>(&page)) return *p;
  if (pages == 0) return notFound("the atlas of job " + id + " is empty");
  const int n = int(std::get<std::optional<long long>>(page).value_or(0));
  res.set_header("X-Atlas-Pages", std::to_string(pages));
  return sendFile(ctx, req, res, id, atlasPageFileName(n), "image/x-exr");
}

using Key = std::tuple<int, int, int, int>;
Key keyOf(const RdmId& id) {
  return {id.slot.x, id.slot.y, id.slot.z, id.level};
}

json entryJson(const AtlasEntry& e) {
  return {{"slot", {e.id.slot.x, e.id.slot.y, e.id.slot.z}},
          {"level", e.id.level},
          {"size", e.id.size},
          {"page", e.page},
          {"rect", {e.x, e.y, 2 * e.id.size, 3 * e.id.size}}};
}

std::optional<Problem> getDelta(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res) {
  const std::string id = req.matches[1];
  if (!req.has_param("from"))
    return badRequest("query parameter 'from' (a job id) is required", "from");
  const std::string from = req.get_param_value("from");
  for (const std::string& j : {id, from}) {
    auto job = succeededJob(ctx, j);
    if (auto* p = std::get_if<Problem>(&job)) return *p;
  }
  auto now_layout = loadLayout(ctx, id), old_layout = loadLayout(ctx, from);
  if (auto* p = std::get_if<Problem>(&now_layout)) return *p;
  if (auto* p = std::get_if<Problem>(&old_layout)) return *p;
  auto now_rec = ctx.jobs.store().loadRdmRecords(id),
       old_rec = ctx.jobs.store().loadRdmRecords(from);
  if (!now_rec || !old_rec) return internalError();
  std::map<Key, std::string> old_origin, now_origin;
  for (const RdmRecord& r : *old_rec) old_origin[keyOf(r.id)] = r.origin_job;
  for (const RdmRecord& r : *now_rec) now_origin[keyOf(r.id)] = r.origin_job;
  std::map<Key, const AtlasEntry*> old_entries;
  for (const AtlasEntry& e : std::get<AtlasLayout>(old_layout).entries)
    old_entries[keyOf(e.id)] = &e;
  json added = json::array(), changed = json::array(), removed = json::array();
  for (const AtlasEntry& e : std::get<AtlasLayout>(now_layout).entries) {
    auto old = old_entries.find(keyOf(e.id));
    if (old == old_entries.end()) {
      added.push_back(entryJson(e));
    } else {
      const AtlasEntry& o = *old->second;
      if (o.id.size != e.id.size || o.page != e.page || o.x != e.x || o.y != e.y ||
          old_origin[keyOf(e.id)] != now_origin[keyOf(e.id)]) {
        changed.push_back(entryJson(e));
      }
      old_entries.erase(old);
    }
  }
  for (const auto& [key, e] : old_entries) removed.push_back(entryJson(*e));
  const AtlasLayout& l = std::get<AtlasLayout>(now_layout);
  json pages = json::array();
  for (const AtlasPage& p : l.pages) pages.push_back({{"width", p.width}, {"height", p.height}});
  sendJson(res, {{"job", id},
                 {"from", from},
                 {"pages", pages},
                 {"added", added},
                 {"changed", changed},
                 {"removed", removed}});
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
  auto layout = loadLayout(ctx, id);
  if (auto* p = std::get_if<Problem>(&layout)) return *p;
  const AtlasEntry* e = std::get<AtlasLayout>(layout).find({v[0], v[1], v[2]}, v[3]);
  if (!e)
    return notFound("job " + id + " has no RDM at slot (" + std::to_string(v[0]) + "," +
                    std::to_string(v[1]) + "," + std::to_string(v[2]) + ") level " +
                    std::to_string(v[3]));
  const std::string name = "rdm-" + std::to_string(v[0]) + "-" + std::to_string(v[1]) + "-" +
                           std::to_string(v[2]) + "-" + std::to_string(v[3]);
  if (handleEtag(req, res, "\"" + id + "/" + name + "\"")) return std::nullopt;
  auto page =
      readExr(ctx.jobs.store().outDir(id) + "/" + atlasPageFileName(e->page), {"R", "G", "B", "Z"});
  if (!page) return internalError();
  Image img(2 * e->id.size, 3 * e->id.size, 4);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 4; ++c) img.at(x, y, c) = page->at(e->x + x, e->y + y, c);
  auto bytes = encodeExr(img, {"R", "G", "B", "Z"});
  if (!bytes) return internalError();
  res.set_content(std::move(*bytes), "image/x-exr");
  return std::nullopt;
}

}  // namespace

void registerResultRoutes(httplib::Server& server, ApiContext& ctx) {
  ApiContext* c = &ctx;
  server.Get(R"(/v1/jobs/([^/]+)/(atlas\.exr|index\.json|index\.txt))",
             wrap([c](const auto& req, auto& res) { return getArtifact(*c, req, res); }));
  server.Get(R"(/v1/jobs/([^/]+)/delta)",
             wrap([c](const auto& req, auto& res) { return getDelta(*c, req, res); }));
  server.Get(R"(/v1/jobs/([^/]+)/rdms/(\d+),(\d+),(\d+)/(\d+)\.exr)",
             wrap([c](const auto& req, auto& res) { return getRdm(*c, req, res); }));
}

}  // namespace rdm::server
