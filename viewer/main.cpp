// rdm-viewer: real-time RDM shading of a voxel scene (docs/spec.md section 6), offscreen or in a
// GLFW window with block editing. Exit status 0 on success, 1 on any failure (including
// no Vulkan device), 2 on a bad command line.
#include <cstdio>

#include "app/options.h"
#include "app/run_modes.h"
#include "rdm/base/build_id.h"

int main(int argc, char** argv) {
  auto options = rdm::viewer::parseViewerOptions(argc, argv);
  if (!options) {
    std::fprintf(stderr, "rdm-viewer: %s\n(rdm-viewer --help lists every option)\n",
                 options.error().c_str());
    return 2;
  }
  if (options->version) {
    std::printf("rdm-viewer %s\n", rdm::buildId().c_str());
    return 0;
  }
  if (options->help) {
    std::printf("%s", rdm::viewer::viewerUsage().c_str());
    return 0;
  }
  if (!options->edit.empty()) return rdm::viewer::runScriptedEdit(*options);
  if (!options->offscreen_png.empty()) return rdm::viewer::runOffscreen(*options);
  return rdm::viewer::runWindow(*options);
}
