// libFuzzer target for the scene loader (docs/spec.md section 2): any input either is refused with
// a message, or parses to a valid scene that round-trips through sceneToJson exactly and compiles
// into a VoxelWorld. Anything else (a crash, a sanitizer report, an exception escaping the loader,
// a broken round trip) aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace {

[[noreturn]] void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "scene_fuzzer: %s: %s\n", what, detail.c_str());
  std::abort();
}

void checkScene(const std::string& text) {
  rdm::Expected<rdm::Scene> scene = rdm::parseSceneJson(text);
  if (!scene.ok()) {
    if (scene.error().empty()) die("refusal without a message", text);
    return;
  }
  rdm::Status valid = rdm::validateScene(*scene);
  if (!valid.ok()) die("parsed scene does not validate", valid.message());

  const std::string json = rdm::sceneToJson(*scene);
  rdm::Expected<rdm::Scene> again = rdm::parseSceneJson(json);
  if (!again.ok()) die("sceneToJson output is refused", again.error());
  if (!(*again == *scene)) die("round trip changed the scene", json);
  if (rdm::sceneToJson(*again) != json) die("sceneToJson is not a fixed point", json);

  rdm::VoxelWorld world = rdm::buildWorld(*scene);
  size_t slots = size_t(scene->size[0]) * size_t(scene->size[1]) * size_t(scene->size[2]);
  if (world.slots.size() != slots) die("world has the wrong slot count", json);
  for (int32_t b : world.slots) {
    if (b < -1 || b >= int32_t(world.blocks.size())) die("slot points past the block list", json);
  }
  if (world.emitters.cdf.size() != world.emitters.emitters.size()) die("emitter cdf size", json);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader reports bad input through Expected; an exception escaping it is a bug.
  try {
    checkScene(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const std::exception& e) {
    die("exception escaped the scene loader", e.what());
  }
  return 0;
}
