// Client of the bake daemon's HTTP API (docs/api.md), used by the `rdm submit / status /
// fetch / cancel` verbs, the viewer's live rebakes and the server tests. Non-2xx answers
// become a Status whose code follows the HTTP status and whose field and message are the
// problem's; transport failures name the server and the cause.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/base/status.h"
#include "rdm/service/job_wire.h"

namespace rdm {

struct HttpReply {
  int status = 0;
  std::string body;
  std::multimap<std::string, std::string> headers;
  std::string header(const std::string& name) const;  // first value, "" when absent
  bool ok() const { return status >= 200 && status < 300; }
};

class BakeClient {
 public:
  // `url` is http://HOST:PORT (no path); `token` empty for none.
  static Expected<std::unique_ptr<BakeClient>> connect(const std::string& url,
                                                       const std::string& token = {});
  ~BakeClient();

  // Raw requests: a transport failure is an error, any HTTP status is a reply.
  Expected<HttpReply> get(const std::string& path,
                          const std::map<std::string, std::string>& headers = {});
  Expected<HttpReply> post(const std::string& path, const std::string& body,
                           const std::string& type = "application/json");
  Expected<HttpReply> patch(const std::string& path, const std::string& body);
  Expected<HttpReply> del(const std::string& path);

  // Typed calls: an HTTP error is an error naming the status and the problem detail.
  Expected<nlohmann::json> uploadScene(const std::string& scene_json);  // {"id", "version", ...}
  Expected<nlohmann::json> submitBake(const std::string& scene_id, const nlohmann::json& request);
  Expected<nlohmann::json> job(const std::string& job_id);
  // Polls until the job is terminal; `on_progress` sees each status. Fails on timeout.
  Expected<nlohmann::json> waitForJob(
      const std::string& job_id, double timeout_s,
      const std::function<void(const nlohmann::json&)>& on_progress = {});
  // Downloads a result file of the job (e.g. "atlas.exr?page=1", "index.json").
  Expected<std::string> download(const std::string& job_id, const std::string& name);

  // The job's status; with wait_s > 0 the daemon answers once `passes` passes are published
  // (0: once the job ended), the job ended, or wait_s seconds passed (long poll, <= 30 s).
  Expected<JobProgress> jobProgress(const std::string& job_id, double wait_s = 0.0, int passes = 0);
  // Every changed rect of the job's pass `pass` (or a later one) since job `from`, in one
  // request (rdm/atlas_delta.h).
  Expected<AtlasDelta> fetchDelta(const std::string& job_id, const std::string& from, int pass);
  Expected<nlohmann::json> patchScene(const std::string& scene_id, const nlohmann::json& patch);
  Expected<nlohmann::json> cancelJob(const std::string& job_id);
  const std::string& url() const;

 private:
  struct Impl;
  explicit BakeClient(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// "HTTP 422: field 'size[0]': ..." from a reply.
std::string describeHttpError(const HttpReply& reply);
// The Status of an error reply: its code follows the HTTP status, its field the problem's.
Status httpErrorStatus(const HttpReply& reply);

}  // namespace rdm
