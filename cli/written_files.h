// The "wrote ..." line of the verbs that write an atlas directory: every file, by name.
#pragma once

#include <cstddef>
#include <string>

namespace rdm::cli {

struct WrittenFiles {
  size_t pages = 1;         // atlas.exr, atlas.page1.exr, ...
  bool noise = false;       // noise.exr and its further pages (rdm bake)
  bool face_light = false;  // face_light.bin
  bool slot_sets = false;   // rdms.bin (rdm bake)
  bool bc6h = false;        // pages as atlas.ktx2 and depth.exr (rdm bake --radiance bc6h)
};

// "DIR/atlas.exr, index.json, index.txt, noise.exr, face_light.bin, rdms.bin,
// bake_report.json": the
// directory once, then the names in the order they are listed here.
std::string writtenFilesLine(const std::string& dir, const WrittenFiles& files);

}  // namespace rdm::cli
