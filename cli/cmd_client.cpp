// `rdm submit`, `rdm status`, `rdm fetch`: the daemon's command-line client.
#include <cstdio>
#include <cstdlib>

#include "args.h"
#include "commands.h"
#include "progress.h"
#include "rdm/client.h"
#include "rdm/file_util.h"
#include "rdm/scene.h"

namespace rdm::cli {
namespace {

using nlohmann::json;

std::unique_ptr<BakeClient> connectFrom(const ArgParser& p, const char* verb) {
  auto url = p.value("--server");
  if (!url) {
    std::fprintf(stderr, "rdm %s: --server URL is required\n", verb);
    return nullptr;
  }
  std::string token;
  if (const char* env = std::getenv("RDM_TOKEN")) token = env;
  if (auto t = p.value("--token")) token = *t;
  auto client = BakeClient::connect(*url, token);
  if (!client) {
    std::fprintf(stderr, "rdm %s: %s\n", verb, client.error().c_str());
    return nullptr;
  }
  return std::move(*client);
}

int fail(const char* verb, const std::string& message) {
  std::fprintf(stderr, "rdm %s: %s\n", verb, message.c_str());
  return 1;
}

bool parseOrUsage(ArgParser& parser, const Args& args, const char* verb, const char* usage,
                  int& code) {
  std::string e = parser.parse(args);
  if (e.empty() && !parser.flag("--help")) return true;
  std::fprintf(stderr, "%s%s",
               e.empty() ? "" : ("rdm " + std::string(verb) + ": " + e + "\n").c_str(), usage);
  code = e.empty() ? 0 : 2;
  return false;
}

}  // namespace

int cmdSubmit(const Args& args) {
  constexpr const char* kUsage =
      "usage: rdm submit (SCENE.json | NAME | --scene-id ID) --server URL [--mode "
      "full|exact|fast]\n"
      "                  [--base-job JOB] [--version N] [--token T]\n"
      "  Uploads the scene (unless --scene-id names one on the server) and submits a bake;\n"
      "  prints the scene id and the job id.\n";
  ArgParser parser({"--server", "--mode", "--base-job", "--version", "--token", "--scene-id"},
                   {"--help"});
  int code = 0;
  if (!parseOrUsage(parser, args, "submit", kUsage, code)) return code;
  auto client = connectFrom(parser, "submit");
  if (!client) return 2;
  std::string scene_id = parser.value("--scene-id").value_or("");
  if (scene_id.empty()) {
    if (parser.positionals().empty())
      return fail("submit", "no scene given (SCENE.json, a built-in name or --scene-id)");
    auto scene = loadSceneByNameOrPath(parser.positionals()[0]);
    if (!scene) return fail("submit", scene.error());
    auto created = client->uploadScene(sceneToJson(*scene));
    if (!created) return fail("submit", created.error());
    scene_id = (*created)["id"];
  }
  json request = json::object();
  if (auto mode = parser.value("--mode")) request["mode"] = *mode;
  if (auto base = parser.value("--base-job")) request["base_job"] = *base;
  std::string error;
  if (auto v = parser.integer("--version", error)) request["version"] = *v;
  if (!error.empty()) return fail("submit", error);
  auto job = client->submitBake(scene_id, request);
  if (!job) return fail("submit", job.error());
  std::printf("scene %s\njob %s\n", scene_id.c_str(), (*job)["id"].get<std::string>().c_str());
  return 0;
}

int cmdStatus(const Args& args) {
  constexpr const char* kUsage = "usage: rdm status JOB --server URL [--token T]\n";
  ArgParser parser({"--server", "--token"}, {"--help"});
  int code = 0;
  if (!parseOrUsage(parser, args, "status", kUsage, code)) return code;
  if (parser.positionals().size() != 1) return std::fprintf(stderr, "%s", kUsage), 2;
  auto client = connectFrom(parser, "status");
  if (!client) return 2;
  auto job = client->job(parser.positionals()[0]);
  if (!job) return fail("status", job.error());
  std::printf("%s\n", job->dump(1).c_str());
  return 0;
}

int cmdFetch(const Args& args) {
  constexpr const char* kUsage =
      "usage: rdm fetch JOB --server URL -o DIR [--timeout SECONDS] [--token T]\n"
      "  Waits for the job (showing progress), then downloads atlas.exr (and further pages),\n"
      "  index.json and index.txt into DIR.\n";
  ArgParser parser({"--server", "--token", "-o", "--output", "--timeout"}, {"--help"});
  int code = 0;
  if (!parseOrUsage(parser, args, "fetch", kUsage, code)) return code;
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (parser.positionals().size() != 1 || !out) return std::fprintf(stderr, "%s", kUsage), 2;
  std::string error;
  const double timeout = parser.number("--timeout", error).value_or(3600.0);
  if (!error.empty()) return fail("fetch", error);
  auto client = connectFrom(parser, "fetch");
  if (!client) return 2;
  const std::string id = parser.positionals()[0];
  ProgressReporter progress("RDMs");
  auto job = client->waitForJob(id, timeout, [&](const json& j) {
    const json& p = j["progress"];
    progress.update(p["rdms_done"], p["rdms_total"], j["rays"], p["elapsed_seconds"]);
  });
  progress.finish();
  if (!job) return fail("fetch", job.error());
  if ((*job)["state"] != "succeeded")
    return fail("fetch", "job " + id + " ended " + (*job)["state"].get<std::string>());
  if (Status s = makeDirectories(*out); !s) return fail("fetch", s.message());
  auto index = client->download(id, "index.json");
  if (!index) return fail("fetch", index.error());
  const size_t pages = json::parse(*index)["pages"].size();
  for (size_t p = 0; p < pages; ++p) {
    auto bytes = client->download(id, "atlas.exr?page=" + std::to_string(p));
    if (!bytes) return fail("fetch", bytes.error());
    const std::string name = p == 0 ? "atlas.exr" : "atlas.page" + std::to_string(p) + ".exr";
    if (Status s = writeFileAtomic(*out + "/" + name, *bytes); !s)
      return fail("fetch", s.message());
  }
  auto text = client->download(id, "index.txt");
  if (!text) return fail("fetch", text.error());
  if (Status s = writeFileAtomic(*out + "/index.json", *index); !s)
    return fail("fetch", s.message());
  if (Status s = writeFileAtomic(*out + "/index.txt", *text); !s) return fail("fetch", s.message());
  std::printf("wrote %zu atlas page(s), index.json and index.txt to %s\n", pages, out->c_str());
  return 0;
}

}  // namespace rdm::cli
