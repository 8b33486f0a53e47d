// Job routes: GET /v1/jobs (newest first, paged), GET (optionally long-polling) and DELETE
// /v1/jobs/{id}.
#include <chrono>

#include "api.h"
#include "http_util.h"
#include "rdm/service/resource_id.h"
#include "status_problem.h"

namespace rdm::server {
namespace {

using nlohmann::json;

double now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::optional<Problem> listJobs(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res) {
  auto limit = queryInt(req, "limit", 1, 100);
  if (auto* p = std::get_if<Problem>(&limit)) return *p;
  const size_t n = size_t(std::get<std::optional<long long>>(limit).value_or(20));
  std::string after = req.has_param("after") ? req.get_param_value("after") : "";
  if (!after.empty() && !validId(after, 'j'))
    return badRequest("query parameter 'after' must be a job id", "after");
  std::vector<JobRecord> jobs = ctx.jobs.list();
  size_t start = 0;
  if (!after.empty()) {
    while (start < jobs.size() && jobs[start].id != after) ++start;
    if (start == jobs.size()) return notFound("no job '" + after + "'");
    ++start;
  }
  json items = json::array();
  const double t = now();
  for (size_t i = start; i < jobs.size() && items.size() < n; ++i)
    items.push_back(jobStatusJson(jobs[i], t));
  json j = {{"jobs", items}, {"total", jobs.size()}};
  const size_t end = start + items.size();
  j["next"] = end < jobs.size()
                  ? json("/v1/jobs?limit=" + std::to_string(n) + "&after=" + jobs[end - 1].id)
                  : json();
  sendJson(res, j);
  return std::nullopt;
}

std::optional<Problem> getJob(ApiContext& ctx, const httplib::Request& req,
                              httplib::Response& res) {
  const std::string id = req.matches[1];
  auto job = validId(id, 'j') ? ctx.jobs.get(id) : std::nullopt;
  if (!job) return notFound("no job '" + id + "'");
  // ?wait=S[&passes=N]: long poll until N passes are published or the job ended (without
  // passes: until it ended), at most S seconds.
  auto wait = queryInt(req, "wait", 0, 30);
  if (auto* p = std::get_if<Problem>(&wait)) return *p;
  auto passes = queryInt(req, "passes", 1, 16);
  if (auto* p = std::get_if<Problem>(&passes)) return *p;
  if (const auto seconds = std::get<std::optional<long long>>(wait)) {
    const int n = int(std::get<std::optional<long long>>(passes).value_or(1 << 20));
    job = ctx.jobs.waitFor(id, n, double(*seconds));
    if (!job) return notFound("no job '" + id + "'");
  }
  const std::string text = jobStatusJson(*job, now()).dump(1) + "\n";
  if (!terminal(job->state)) res.set_header("Retry-After", "1");
  if (handleEtag(req, res, bodyEtag(text))) return std::nullopt;
  res.set_content(text, "application/json");
  return std::nullopt;
}

// An unfinished job is cancelled (202 with the job; 409 once it writes its results); a
// finished one is deleted with its files (204; 409 naming the kept jobs that need it), unless
// ?finished=keep asks for a cancel only (409 for a finished job: `rdm cancel` never deletes).
std::optional<Problem> deleteJob(ApiContext& ctx, const httplib::Request& req,
                                 httplib::Response& res) {
  const std::string id = req.matches[1];
  const bool cancel_only = req.has_param("finished");
  if (cancel_only && req.get_param_value("finished") != "keep")
    return badRequest("query parameter 'finished' must be 'keep'", "finished");
  auto found = validId(id, 'j') ? ctx.jobs.get(id) : std::nullopt;
  if (!found) return notFound("no job '" + id + "'");
  if (terminal(found->state) && !cancel_only) {
    if (Status s = ctx.jobs.removeJob(id); !s) return problemOf(s);
    res.status = 204;
    return std::nullopt;
  }
  auto job = ctx.jobs.cancel(id);
  if (!job) return problemOf(job.status());
  sendJson(res, jobStatusJson(*job, now()), 202);
  return std::nullopt;
}

}  // namespace

void registerJobRoutes(httplib::Server& server, ApiContext& ctx) {
  ApiContext* c = &ctx;
  server.Get("/v1/jobs", wrap([c](const auto& req, auto& res) { return listJobs(*c, req, res); }));
  server.Get(R"(/v1/jobs/([^/]+))",
             wrap([c](const auto& req, auto& res) { return getJob(*c, req, res); }));
  server.Delete(R"(/v1/jobs/([^/]+))",
                wrap([c](const auto& req, auto& res) { return deleteJob(*c, req, res); }));
}

}  // namespace rdm::server
