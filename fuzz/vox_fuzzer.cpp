// libFuzzer target for the MagicaVoxel importer: any bytes either import into a scene that
// validates and round-trips through JSON, or are refused with a Status; nothing crashes.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rdm/scene/vox_import.h"
#include "rdm/scene/world.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto scene = rdm::importVox(std::string(reinterpret_cast<const char*>(data), size));
  if (!scene.ok()) return 0;
  if (!rdm::validateScene(*scene).ok()) std::abort();
  auto back = rdm::parseSceneJson(rdm::sceneToJson(*scene));
  if (!back.ok() || !(*back == *scene)) std::abort();
  rdm::buildWorld(*scene);
  return 0;
}
