// libFuzzer target for scene patches (docs/spec.md section 8.3, rdm/scene/scene_patch.h), the body
// of PATCH /v1/scenes/{id}: parsed as the daemon parses bodies, then applied to a built-in
// scene. Any input either is refused with a message, or gives a valid scene for which
// makeScenePatch(base, patched) applied to the base gives the patched scene again (the one
// PATCH format the daemon applies and the viewer and the CLI write). Anything else (a crash,
// a sanitizer report, an escaping exception, a patch that does not reproduce) aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "rdm/base/json_parse.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/scene_patch.h"

namespace {

[[noreturn]] void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "patch_fuzzer: %s: %s\n", what, detail.c_str());
  std::abort();
}

void checkPatch(const rdm::Scene& base, const std::string& text) {
  nlohmann::json body;
  if (rdm::Status parsed = rdm::parseJsonLimited(text, body); !parsed) {
    if (parsed.message().empty()) die("JSON refusal without a message", text);
    return;
  }
  rdm::Expected<rdm::Scene> patched = rdm::applyScenePatch(base, body);
  if (!patched.ok()) {
    if (patched.error().empty()) die("refusal without a message", text);
    return;
  }
  if (rdm::Status valid = rdm::validateScene(*patched); !valid.ok())
    die("patched scene does not validate", valid.message());
  const nlohmann::json again = rdm::makeScenePatch(base, *patched, 1);
  rdm::Expected<rdm::Scene> replayed = rdm::applyScenePatch(base, again);
  if (!replayed.ok()) die("makeScenePatch output is refused", replayed.error());
  if (!(*replayed == *patched)) die("makeScenePatch does not reproduce the patch", again.dump());
  if (rdm::scenePatchIsEmpty(again) != (*patched == base))
    die("an empty patch and an unchanged scene disagree", again.dump());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rdm::Scene base = rdm::builtinScene("chess").value();
  try {
    checkPatch(base, std::string(reinterpret_cast<const char*>(data), size));
  } catch (const std::exception& e) {
    die("exception escaped", e.what());
  }
  return 0;
}
