#include "rdm/service/stored_file.h"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "rdm/atlas/rdm_store.h"
#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"
#include "rdm/base/log.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kManifestFormat = 1;

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// Files the manifest leaves out: itself, temporaries (`<name>.tmp.<pid>.<n>`), quarantined
// files and the per-RDM store, which checks itself per RDM.
bool listed(const std::string& name) {
  return name != kChecksumsFile && name != kRdmStoreFile &&
         name.find(".tmp.") == std::string::npos && !endsWith(name, kCorruptSuffix);
}

Status corrupt(const std::string& path, const std::string& what) {
  return Status::error(StatusCode::kCorrupt, path + ": " + what);
}

}  // namespace

std::string hashHex(uint64_t hash) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(hash));
  return buf;
}

std::optional<uint64_t> parseHashHex(const std::string& text) {
  if (text.size() != 16) return std::nullopt;
  uint64_t v = 0;
  for (char c : text) {
    int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (d < 0) return std::nullopt;
    v = v << 4 | uint64_t(d);
  }
  return v;
}

void reportCorrupt(const std::string& path, const std::string& expected, const std::string& actual,
                   bool quarantine_file) {
  json fields = {{"path", path}, {"expected", expected}, {"actual", actual}};
  if (quarantine_file) {
    std::error_code ec;
    fs::rename(path, path + kCorruptSuffix, ec);
    fields["quarantined"] = ec ? "" : path + kCorruptSuffix;
    if (ec) fields["rename_error"] = ec.message();
  }
  logEvent(LogLevel::kError, "corrupt", fields);
}

Status writeResultChecksums(const std::string& dir) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || !listed(name)) continue;
    auto bytes = readFileToString(entry.path().string());
    if (!bytes) return bytes.status();
    files[name] = hashHex(contentHash(*bytes));
  }
  if (ec) return Status::error(StatusCode::kIo, dir + ": " + ec.message());
  const json listing = files;
  const json manifest = {{"format", kManifestFormat},
                         {"files", listing},
                         {"check", hashHex(contentHash(listing.dump()))}};
  return writeFileAtomic(dir + "/" + kChecksumsFile, manifest.dump(1) + "\n");
}

Expected<std::map<std::string, uint64_t>> readResultChecksums(const std::string& dir) {
  const std::string path = dir + "/" + kChecksumsFile;
  std::error_code ec;
  if (!fs::exists(path, ec))
    return Status::notFound(path + ": no checksums (a job from before result checksums)");
  auto text = readFileToString(path);
  if (!text) return text.status();
  std::map<std::string, uint64_t> out;
  try {
    const json manifest = json::parse(*text);
    const json& listing = manifest.at("files");
    const std::string check = manifest.at("check").get<std::string>();
    if (manifest.at("format").get<int>() != kManifestFormat)
      return corrupt(path, "unknown manifest format");
    if (hashHex(contentHash(listing.dump())) != check)
      return corrupt(path, "the manifest fails its own checksum");
    for (const auto& [name, hex] : listing.items()) {
      auto hash = parseHashHex(hex.get<std::string>());
      if (!hash) return corrupt(path, "a malformed hash for " + name);
      out[name] = *hash;
    }
  } catch (const std::exception&) {
    return corrupt(path, "the manifest is torn or not JSON");
  }
  return out;
}

Expected<VerifiedFile> readVerifiedResult(const std::string& dir, const std::string& name) {
  const std::string path = dir + "/" + name;
  std::error_code ec;
  auto manifest = readResultChecksums(dir);
  if (!manifest && manifest.status().code() != StatusCode::kNotFound) {
    logEvent(LogLevel::kError, "corrupt",
             {{"path", dir + "/" + kChecksumsFile}, {"expected", ""}, {"actual", "unreadable"}});
    return manifest.status();
  }
  if (fs::exists(path + kCorruptSuffix, ec) && !fs::exists(path, ec))
    return corrupt(path,
                   "failed its checksum earlier and was moved aside to " + name + kCorruptSuffix);
  std::optional<uint64_t> expected;
  if (manifest) {
    auto it = manifest->find(name);
    if (it != manifest->end()) expected = it->second;
  }
  auto bytes = readFileToString(path);
  if (!bytes) {
    if (fs::exists(path, ec)) return bytes.status();
    if (!expected) return Status::notFound(path + ": no such result file");
    reportCorrupt(path, hashHex(*expected), "missing", false);
    return corrupt(path, "listed in " + std::string(kChecksumsFile) + " but gone");
  }
  VerifiedFile out;
  out.hash = contentHash(*bytes);
  out.bytes = std::move(*bytes);
  out.verified = expected.has_value();
  if (expected && *expected != out.hash) {
    reportCorrupt(path, hashHex(*expected), hashHex(out.hash));
    return corrupt(path, "fails its checksum (expected " + hashHex(*expected) + ", read " +
                             hashHex(out.hash) + "); moved aside to " + name + kCorruptSuffix);
  }
  return out;
}

}  // namespace rdm
