// The viewer's LDR-FLIP against a path-traced reference, through the real binaries (rdm-viewer
// offscreen, `rdm flip`). Built with the viewer only.
#pragma once

#include <cstdlib>
#include <string>

#include "cli_run.h"

namespace rdm {

// LDR-FLIP of the viewer's image against DIR/ref.exr, camera 0 at 320 x 180, 16 jittered frames,
// with the given terms, from the atlas DIR/atlas; the image is DIR/NAME.exr. -1 on any failure.
inline double viewerFlip(const std::string& dir, const std::string& scene, const std::string& terms,
                         const std::string& name) {
  const std::string image = dir + "/" + name + ".exr";
  const std::string view = std::string(RDM_VIEWER_BINARY) + " --scene " + scene +
                           " --camera 0 --atlas " + dir + "/atlas --width 320 --height 180 " +
                           "--aa 16 --terms " + terms + " --offscreen " + dir + "/view.png --exr " +
                           image + " > /dev/null 2>&1";
  if (std::system(view.c_str()) != 0) return -1.0;
  const CliResult flip = runRdm("flip " + dir + "/ref.exr " + image + " --ppd 67.02");
  const size_t at = flip.out.find("mean LDR-FLIP: ");
  return flip.code == 0 && at != std::string::npos ? std::atof(flip.out.c_str() + at + 15) : -1.0;
}

}  // namespace rdm
