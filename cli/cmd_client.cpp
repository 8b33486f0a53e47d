// `rdm submit`, `rdm status`, `rdm fetch`, `rdm cancel`: the daemon's command-line client.
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <utility>
#include <vector>

#include "cli_app.h"
#include "commands.h"
#include "output_check.h"
#include "progress.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/bake/face_light.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "rdm/service/scene_push.h"
#include "scene_options.h"
#include "server_errors.h"
#include "written_files.h"

namespace rdm::cli {
namespace {

using nlohmann::json;

struct ServerArgs {
  std::string url, token;
};

void addServerOptions(CLI::App& app, ServerArgs& s) {
  app.add_option("--server", s.url, "daemon URL, http://HOST:PORT")->required();
  app.add_option("--token", s.token, "bearer token")->default_str("$RDM_TOKEN");
}

class Session {
 public:
  Session(const char* verb, const ServerArgs& args) : verb_(verb), url_(args.url) {
    std::string token = args.token;
    if (const char* env = std::getenv("RDM_TOKEN"); env && token.empty()) token = env;
    auto client = BakeClient::connect(url_, token);
    if (client) {
      client_ = std::move(*client);
    } else {
      error_ = client.error();
    }
  }
  BakeClient* operator->() { return client_.get(); }
  BakeClient& operator*() { return *client_; }
  explicit operator bool() const { return client_ != nullptr; }
  int connectFailed() const { return fail(verb_, error_, 2); }
  int failed(const std::string& message) const {
    return fail(verb_, describeServerError(url_, message));
  }

 private:
  const char* verb_;
  std::string url_, error_;
  std::unique_ptr<BakeClient> client_;
};

std::string text(const json& j, const char* key) {
  return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string("-");
}

// The running job's phase in words (docs/api.md "phase"), ", " first; empty otherwise.
std::string phaseText(const json& progress) {
  const std::string phase = progress.contains("phase") && progress["phase"].is_string()
                                ? progress["phase"].get<std::string>()
                                : "";
  if (phase == "preparing") return ", preparing";
  if (phase == "rdms") return ", baking RDMs";
  if (phase == "face_light") return ", baking the face light";
  if (phase == "results") return ", writing results";
  return "";
}

double number(const json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : 0.0;
}

void printJobSummary(const json& job) {
  const json& p = job.value("progress", json::object());
  const json& r = job.value("rdms", json::object());
  std::printf("job:       %s (scene %s, version %lld)\n", text(job, "id").c_str(),
              text(job, "scene").c_str(), (long long)number(job, "scene_version"));
  std::printf("state:     %s%s\n", text(job, "state").c_str(),
              job.value("cancel_requested", false) ? " (cancel requested)" : "");
  std::printf("pass:      %s bake%s\n", text(job, "mode").c_str(),
              job.contains("base_job") && job["base_job"].is_string()
                  ? (" on top of " + job["base_job"].get<std::string>()).c_str()
                  : "");
  if (job.contains("backend") && job["backend"].is_string()) {
    const bool device = job.contains("device") && job["device"].is_string();
    std::printf("backend:   %s%s\n", text(job, "backend").c_str(),
                device ? (" on " + job["device"].get<std::string>()).c_str() : "");
  }
  std::string eta = p.contains("eta_seconds") && p["eta_seconds"].is_number()
                        ? ", ETA " + formatDuration(p["eta_seconds"].get<double>())
                        : "";
  const long long faces_total = (long long)number(p, "face_light_faces_total");
  const std::string faces =
      faces_total > 0 ? ", " + std::to_string((long long)number(p, "face_light_faces_done")) + "/" +
                            std::to_string(faces_total) + " face-light faces"
                      : "";
  const std::string phase = phaseText(p);
  std::printf("progress:  %.1f %% (%lld/%lld RDMs%s%s), %s elapsed%s\n",
              100.0 * number(p, "fraction"), (long long)number(p, "rdms_done"),
              (long long)number(p, "rdms_total"), faces.c_str(), phase.c_str(),
              formatDuration(number(p, "elapsed_seconds")).c_str(), eta.c_str());
  std::printf("RDMs:      %lld in the scene, %lld re-baked, %lld copied from the base job\n",
              (long long)number(r, "scene"), (long long)number(r, "rebaked"),
              (long long)number(r, "copied"));
  if (job.contains("error") && job["error"].is_string())
    std::printf("error:     %s\n", job["error"].get<std::string>().c_str());
}

// bake_report.json for a fetched job, from the job's status (the daemon keeps no report).
json reportFromJob(const json& job) {
  json report = {{"job", job.value("id", "")},
                 {"scene", job.value("scene", "")},
                 {"mode", job.value("mode", "")},
                 {"build", job.value("build", "")},
                 {"backend", job.value("backend", "cpu")},
                 {"device", job.value("device", json())},
                 {"rays", job.value("rays", json())},
                 {"texels", job.value("texels", json())},
                 {"rdms", job.value("rdms", json())},
                 {"units", job.value("units", json())},
                 {"timings", job.value("timings", json())},
                 {"effects_simulated", job.value("effects", json::object()).value("simulated", "")},
                 {"effects_skipped", job.value("effects", json::object()).value("skipped", "")},
                 {"source", "daemon job status"}};
  if (const json noise = job.value("noise", json()); noise.is_object()) report.update(noise);
  if (job.contains("settings")) {
    for (const auto& [k, v] : job["settings"].items()) report[k] = v;
  }
  return report;
}

}  // namespace

namespace {

// SOURCE of `rdm patch`: a PATCH document (an object with base_version or edits and no size),
// or a scene (file, built-in name or .vox) the server's scene is brought to.
struct PatchSource {
  std::optional<json> patch;
  std::optional<Scene> scene;
};

Expected<PatchSource> loadPatchSource(const std::string& source) {
  if (auto text = readFileToString(source)) {
    json j = json::parse(*text, nullptr, false);
    if (j.is_object() && !j.contains("size") && (j.contains("base_version") || j.contains("edits")))
      return PatchSource{std::move(j), std::nullopt};
  }
  auto scene = loadSceneArgument(source);
  if (!scene) return scene.status();
  return PatchSource{std::nullopt, std::move(*scene)};
}

Expected<ScenePushed> push(BakeClient& client, const std::string& scene_id,
                           const PatchSource& source) {
  if (source.patch) return pushPatch(client, scene_id, *source.patch);
  return pushScene(client, scene_id, *source.scene);
}

}  // namespace

int cmdSubmit(const Args& args) {
  std::string scene_source, scene_id, mode, base_job, radiance;
  int face_light = -1;  // -1: the scene's
  bool denoise = false;
  long long version = 0;
  ServerArgs server;
  VerbApp app("submit",
              "Upload a scene to a daemon and submit a bake; prints the scene id and the job id. "
              "With --scene-id the server's scene is brought to SCENE first by one PATCH of the "
              "difference (rdm patch), and the bake is of the version that makes.");
  app.add_option("SCENE", scene_source, "scene JSON file, .vox or built-in name");
  app.add_option("--scene-id", scene_id, "a scene already on the server")->default_str("none");
  app.add_option("--mode", mode, "full, exact or fast (docs/api.md)")->default_str("full");
  app.add_option("--base-job", base_job, "job to re-bake incrementally from")->default_str("none");
  app.add_option("--version", version, "scene version")->default_str("latest");
  app.add_option("--radiance", radiance, "atlas radiance: float32, half or bc6h (docs/api.md)")
      ->check(CLI::IsMember({"float32", "half", "bc6h"}))
      ->default_str("float32");
  app.add_option("--face-light", face_light,
                 "bake the light of every voxel face at N samples (face_light.bin; 0: none)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("the scene's bake.face_light_spp");
  app.add_flag("--denoise", denoise,
               "filter the job's RDMs across block borders before they are written "
               "(docs/denoise.md)");
  addServerOptions(app, server);
  if (auto code = parseArgs(app, args)) return *code;
  if (scene_id.empty() && scene_source.empty())
    return fail("submit", "no scene given (SCENE.json, a built-in name or --scene-id)", 2);
  if (!scene_id.empty() && !scene_source.empty() && version)
    return fail("submit",
                "--version with SCENE and --scene-id: the bake is of the version "
                "SCENE makes; give one of them",
                2);
  Session client("submit", server);
  if (!client) return client.connectFailed();
  if (scene_id.empty()) {
    auto scene = loadSceneArgument(scene_source);
    if (!scene) return fail("submit", scene.error());
    auto created = client->uploadScene(sceneToJson(*scene));
    if (!created) return client.failed(created.error());
    scene_id = (*created)["id"];
  } else if (!scene_source.empty()) {
    auto source = loadPatchSource(scene_source);
    if (!source) return fail("submit", source.error());
    auto pushed = push(*client, scene_id, *source);
    if (!pushed) return client.failed(pushed.error());
    std::printf("scene %s %s\n", scene_id.c_str(), describePush(*pushed).c_str());
    version = pushed->version;
  }
  json request = json::object();
  if (!mode.empty()) request["mode"] = mode;
  if (!base_job.empty()) request["base_job"] = base_job;
  if (version) request["version"] = version;
  if (!radiance.empty()) request["radiance"] = radiance;
  if (face_light >= 0) request["face_light"] = face_light;
  if (denoise) request["denoise"] = true;
  auto job = client->submitBake(scene_id, request);
  if (!job) return client.failed(job.error());
  std::printf("scene %s\njob %s\n", scene_id.c_str(), (*job)["id"].get<std::string>().c_str());
  return 0;
}

int cmdPatch(const Args& args) {
  std::string scene_id, source;
  ServerArgs server;
  VerbApp app("patch",
              "Change a scene on a daemon: SOURCE is a PATCH document (docs/api.md) or a whole "
              "scene, whose difference from the server's current version is sent as one "
              "PATCH. Prints the new version and what changed; submit a bake with "
              "`rdm submit --scene-id ID --mode exact` to re-light only what changed.");
  app.add_option("SCENE_ID", scene_id, "the scene on the server")->required();
  app.add_option("SOURCE", source, "PATCH JSON, scene JSON, .vox or built-in name")->required();
  addServerOptions(app, server);
  if (auto code = parseArgs(app, args)) return *code;
  auto loaded = loadPatchSource(source);
  if (!loaded) return fail("patch", loaded.error());
  Session client("patch", server);
  if (!client) return client.connectFailed();
  auto pushed = push(*client, scene_id, *loaded);
  if (!pushed) return client.failed(pushed.error());
  std::printf("scene %s %s\n", scene_id.c_str(), describePush(*pushed).c_str());
  return 0;
}

int cmdStatus(const Args& args) {
  std::string id;
  bool as_json = false;
  ServerArgs server;
  VerbApp app("status", "Show a daemon job: state, pass, progress, ETA, RDMs re-baked.");
  app.add_option("JOB", id, "job id")->required();
  app.add_flag("--json", as_json, "print the job's JSON status instead");
  addServerOptions(app, server);
  if (auto code = parseArgs(app, args)) return *code;
  Session client("status", server);
  if (!client) return client.connectFailed();
  auto job = client->job(id);
  if (!job) return client.failed(job.error());
  if (as_json) {
    std::printf("%s\n", job->dump(1).c_str());
  } else {
    printJobSummary(*job);
  }
  return 0;
}

int cmdCancel(const Args& args) {
  std::string id;
  ServerArgs server;
  VerbApp app("cancel",
              "Cancel a daemon job (DELETE /v1/jobs/JOB?finished=keep); it stops after the "
              "work units in progress. A job that has already ended is left as it is.");
  app.add_option("JOB", id, "job id")->required();
  addServerOptions(app, server);
  if (auto code = parseArgs(app, args)) return *code;
  Session client("cancel", server);
  if (!client) return client.connectFailed();
  auto reply = client->del("/v1/jobs/" + id + "?finished=keep");  // a cancel, never a delete
  if (!reply) return client.failed(reply.error());
  if (reply->status == 409) {
    auto job = client->job(id);
    if (job && job->value("state", "") != "running" && job->value("state", "") != "queued") {
      std::printf("job %s has already ended (%s): nothing to cancel\n", id.c_str(),
                  text(*job, "state").c_str());
      return 0;
    }
  }
  if (!reply->ok()) return client.failed(describeHttpError(*reply));
  json job = json::parse(reply->body, nullptr, false);
  const std::string state = job.is_object() ? text(job, "state") : "-";
  std::printf("job %s: cancel requested (state now %s)\n", id.c_str(), state.c_str());
  return 0;
}

int cmdFetch(const Args& args) {
  std::string id, out;
  double timeout = 3600.0;
  ServerArgs server;
  VerbApp app("fetch",
              "Wait for a daemon job (showing progress), then download atlas.exr "
              "(a bc6h job: atlas.ktx2 and depth.exr; and further pages), index.json, index.txt, "
              "face_light.bin (when baked) and "
              "bake_report.json into DIR.");
  app.add_option("JOB", id, "job id")->required();
  app.add_option("-o,--output", out, "output directory (checked before waiting)")->required();
  app.add_option("--timeout", timeout, "seconds to wait for the job")->check(CLI::PositiveNumber);
  addServerOptions(app, server);
  if (auto code = parseArgs(app, args)) return *code;
  bool created = false;
  if (Status s = prepareOutputDirectory(out, created); !s) return fail("fetch", s.message());
  Session client("fetch", server);
  if (!client) return client.connectFailed();
  ProgressReporter progress("RDMs");
  auto job = client->waitForJob(id, timeout, [&](const json& j) {
    const json& p = j["progress"];
    const json& t = j["texels"];
    progress.update(number(t, "done"), number(t, "total"), int(number(p, "rdms_done")),
                    int(number(p, "rdms_total")), uint64_t(number(j, "rays")),
                    number(p, "elapsed_seconds"));
  });
  progress.finish();
  if (!job) {
    if (created) removeIfEmpty(out);
    return client.failed(job.error());
  }
  if ((*job)["state"] != "succeeded") {
    if (created) removeIfEmpty(out);
    return fail("fetch", "job " + id + " ended " + text(*job, "state") +
                             (job->contains("error") && (*job)["error"].is_string()
                                  ? ": " + (*job)["error"].get<std::string>()
                                  : ""));
  }
  auto index = client->download(id, "index.json");
  if (!index) return client.failed(index.error());
  const json parsed = json::parse(*index, nullptr, false);
  if (!parsed.is_object() || !parsed.contains("pages"))
    return fail("fetch", "server " + server.url + " sent an index.json without pages");
  const size_t pages = parsed["pages"].size();
  const bool bc6h = parsed.value("radiance", "") == "bc6h";
  // Each page's files: (route, file name).
  std::vector<std::pair<std::string, std::string>> files;
  for (size_t p = 0; p < pages; ++p) {
    const std::string query = "?page=" + std::to_string(p);
    if (bc6h) {
      files.push_back({"atlas.ktx2" + query, atlasKtx2FileName(int(p))});
      files.push_back({"depth.exr" + query, atlasDepthFileName(int(p))});
    } else {
      files.push_back({"atlas.exr" + query, atlasPageFileName(int(p))});
    }
  }
  for (const auto& [route, name] : files) {
    auto bytes = client->download(id, route);
    if (!bytes) return client.failed(bytes.error());
    if (Status s = writeFileAtomic(out + "/" + name, *bytes); !s) return fail("fetch", s.message());
  }
  const bool noise = job->value("mode", "") == "full" && job->value("noise", json()).is_object();
  for (size_t p = 0; noise && p < pages; ++p) {
    auto bytes = client->download(id, "noise.exr?page=" + std::to_string(p));
    if (!bytes) return client.failed(bytes.error());
    if (Status s = writeFileAtomic(out + "/" + noisePageFileName(int(p)), *bytes); !s)
      return fail("fetch", s.message());
  }
  auto index_text = client->download(id, "index.txt");
  if (!index_text) return client.failed(index_text.error());
  if (job->value("face_light", 0) > 0) {
    auto light = client->download(id, kFaceLightFile);
    if (!light) return client.failed(light.error());
    if (Status s = writeFileAtomic(out + "/" + kFaceLightFile, *light); !s)
      return fail("fetch", s.message());
  }
  for (const auto& [name, contents] : {std::pair<std::string, std::string>{"index.json", *index},
                                       {"index.txt", *index_text},
                                       {"bake_report.json", reportFromJob(*job).dump(1) + "\n"}}) {
    if (Status s = writeFileAtomic(out + "/" + name, contents); !s)
      return fail("fetch", s.message());
  }
  WrittenFiles written{pages, noise, job->value("face_light", 0) > 0};
  written.bc6h = bc6h;
  std::printf("wrote %s\n", writtenFilesLine(out, written).c_str());
  return 0;
}

}  // namespace rdm::cli
