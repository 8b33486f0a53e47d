#include "atlas_input.h"

#include <filesystem>

namespace rdm::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kWhatAnAtlasIs =
    "an atlas directory, written by rdm bake, merge or fetch, holds index.json and atlas.exr";

}  // namespace

Status checkAtlasDirectory(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec))
    return Status::error(dir + ": no such file or directory (" + kWhatAnAtlasIs + ")");
  if (!fs::is_directory(dir, ec))
    return Status::error(dir + ": not a directory (" + kWhatAnAtlasIs + ")");
  if (!fs::exists(fs::path(dir) / "index.json", ec))
    return Status::error(dir + ": no index.json in it (" + kWhatAnAtlasIs + ")");
  return {};
}

Expected<std::string> exrFileFor(const std::string& in) {
  std::error_code ec;
  if (!fs::is_directory(in, ec)) return in;
  const std::string atlas = (fs::path(in) / "atlas.exr").string();
  if (fs::exists(atlas, ec)) return atlas;
  return Status::error(in + ": a directory without atlas.exr (" + kWhatAnAtlasIs +
                       "); or give an .exr file");
}

}  // namespace rdm::cli
