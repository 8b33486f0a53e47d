#include "written_files.h"

#include "rdm/atlas/atlas.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/unit_checkpoint.h"

namespace rdm::cli {
namespace {

// Up to 4 pages by name; more as the first, the second and the last ("a, b ... z").
std::string pageNames(size_t pages, std::string (*name)(int)) {
  std::string out = name(0);
  for (size_t p = 1; p < pages; ++p) {
    const bool elided = pages > 4 && p >= 2 && p + 1 < pages;
    if (elided) continue;
    out += (pages > 4 && p + 1 == pages ? " ... " : ", ") + name(int(p));
  }
  return out;
}

}  // namespace

std::string writtenFilesLine(const std::string& dir, const WrittenFiles& files) {
  std::string line = dir + "/" +
                     (files.bc6h ? pageNames(files.pages, atlasKtx2FileName) + ", " +
                                       pageNames(files.pages, atlasDepthFileName)
                                 : pageNames(files.pages, atlasPageFileName));
  line += ", index.json, index.txt";
  if (files.noise) line += ", " + pageNames(files.pages, noisePageFileName);
  if (files.face_light) line += std::string(", ") + kFaceLightFile;
  if (files.slot_sets) line += std::string(", ") + kRdmRecordsFile;
  return line + ", bake_report.json";
}

}  // namespace rdm::cli
