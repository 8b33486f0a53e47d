// libFuzzer target for bake requests, the body of POST /v1/scenes/{id}/bakes (docs/api.md):
// parsed as the daemon parses bodies (parseJsonBody), then read by parseBakeRequest against
// a built-in scene under the default server limits. Any input is either refused with a 4xx
// problem that says what is wrong, or gives a request the daemon can run: settings that
// validate and pass the limits, and a base job only for the incremental modes. Anything else
// (a crash, a sanitizer report, an escaping exception, a request that breaks those rules)
// aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "api.h"
#include "http_util.h"
#include "rdm/scene/scene.h"
#include "server_config.h"
#include "status_problem.h"

namespace {

[[noreturn]] void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "bake_request_fuzzer: %s: %s\n", what, detail.c_str());
  std::abort();
}

void checkRefusal(const rdm::Status& refusal, const std::string& text) {
  const rdm::server::Problem p = rdm::server::problemOf(refusal);
  if (p.status < 400 || p.status > 499) die("refusal is not a 4xx", std::to_string(p.status));
  if (p.detail.empty()) die("refusal without a detail", text);
}

void checkBakeRequest(const rdm::Scene& scene, const rdm::server::ServerConfig& config,
                      const std::string& text) {
  auto parsed = rdm::server::parseJsonBody(text);
  if (!parsed) return checkRefusal(parsed.status(), text);
  auto request = rdm::server::parseBakeRequest(*parsed, scene, config);
  if (!request) return checkRefusal(request.status(), text);
  const rdm::SubmitRequest& r = *request;
  rdm::Scene baked = scene;
  baked.bake = r.settings;
  if (rdm::Status valid = rdm::validateScene(baked); !valid.ok())
    die("accepted settings do not validate", valid.message());
  if (rdm::Status over = rdm::server::checkSettingsLimits(r.settings, config, "settings"); !over)
    die("accepted settings are over the limits", over.message());
  if (!r.base_job.empty() && r.mode == rdm::BakeMode::kFull)
    die("a full bake was given a base job", text);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rdm::Scene scene = rdm::builtinScene("chess").value();
  static const rdm::server::ServerConfig config;
  try {
    checkBakeRequest(scene, config, std::string(reinterpret_cast<const char*>(data), size));
  } catch (const std::exception& e) {
    die("exception escaped", e.what());
  }
  return 0;
}
