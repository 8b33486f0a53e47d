// libFuzzer target for the MagicaVoxel importer: any bytes either import into a scene that
// validates and round-trips through JSON, or are refused with a Status; nothing crashes. Each
// input is imported twice: with the defaults, and at frame 1 with layer 1 and the ground.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rdm/scene/vox_import.h"
#include "rdm/scene/world.h"

namespace {

void check(const std::string& bytes, const rdm::VoxImportOptions& options) {
  auto scene = rdm::importVox(bytes, options);
  if (!scene.ok()) return;
  if (!rdm::validateScene(*scene).ok()) std::abort();
  auto back = rdm::parseSceneJson(rdm::sceneToJson(*scene));
  if (!back.ok() || !(*back == *scene)) std::abort();
  rdm::buildWorld(*scene);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  check(bytes, {});
  rdm::VoxImportOptions options;
  options.frame = 1;
  options.layers = {"1"};
  options.ground = true;
  check(bytes, options);
  return 0;
}
