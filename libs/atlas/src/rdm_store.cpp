#include "rdm/atlas/rdm_store.h"

#include <cstdio>
#include <cstring>
#include <fstream>

#include "rdm/base/binary_io.h"
#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"
#include "rdm/base/log.h"

namespace rdm {
namespace {

constexpr uint64_t kStoreMagicV1 = 0x31524f54534d4452ull;  // "RDMSTOR1": no checksums
constexpr uint64_t kStoreMagic = 0x32524f54534d4452ull;    // "RDMSTOR2"
constexpr uint32_t kMaxEntries = 1u << 24;
constexpr size_t kEntryBytesV1 = 5 * sizeof(int32_t) + sizeof(uint64_t);
constexpr size_t kEntryBytes = kEntryBytesV1 + sizeof(uint64_t);  // + the texels' XXH3

std::string hex16(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

uint64_t imageBytes(int size) {
  return uint64_t(2 * size) * uint64_t(3 * size) * 4 * sizeof(float);
}

}  // namespace

Status writeRdmStore(const std::string& path, const RdmSource& rdms) {
  const std::vector<RdmId> ids = rdms.ids();
  auto file = AtomicFileWriter::create(path);
  if (!file) return file.status();
  BinaryWriter w;
  w.put(kStoreMagic);
  w.put(uint32_t(ids.size()));
  uint64_t offset = sizeof(uint64_t) + sizeof(uint32_t) + ids.size() * kEntryBytes;
  for (size_t i = 0; i < ids.size(); ++i) {
    const RdmId& id = ids[i];
    uint64_t hash = 0;
    const Status read = rdms.visit(i, [&](const RdmData& r) {
      RDM_CHECK(r.image.pixels.size() * sizeof(float) == imageBytes(r.id.size));
      const std::string_view bytes(reinterpret_cast<const char*>(r.image.pixels.data()),
                                   r.image.pixels.size() * sizeof(float));
      hash = contentHash(bytes);
      (*file)->writeAt(offset, bytes.data(), bytes.size());
    });
    if (!read) return read;
    w.put(int32_t(id.slot.x)), w.put(int32_t(id.slot.y)), w.put(int32_t(id.slot.z));
    w.put(int32_t(id.level)), w.put(int32_t(id.size)), w.put(offset), w.put(hash);
    offset += imageBytes(id.size);
  }
  (*file)->writeAt(0, w.bytes().data(), w.bytes().size());
  return (*file)->commit();
}

Expected<RdmStoreReader> RdmStoreReader::open(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return Status::notFound(path + ": cannot open the per-RDM store");
  RdmStoreReader reader;
  reader.path_ = path;
  reader.file_size_ = uint64_t(in.tellg());
  in.seekg(0);
  std::string head(sizeof(uint64_t) + sizeof(uint32_t), '\0');
  in.read(head.data(), std::streamsize(head.size()));
  uint64_t magic = 0;
  uint32_t count = 0;
  BinaryReader hr(head);
  if (!in || !hr.get(magic) || !hr.get(count) || (magic != kStoreMagic && magic != kStoreMagicV1) ||
      count > kMaxEntries)
    return Status::error(StatusCode::kCorrupt, path + ": not a per-RDM store");
  const bool checksums = magic == kStoreMagic;
  std::string toc(size_t(count) * (checksums ? kEntryBytes : kEntryBytesV1), '\0');
  in.read(toc.data(), std::streamsize(toc.size()));
  if (!in) return Status::error(StatusCode::kCorrupt, path + ": table of contents cut short");
  BinaryReader tr(toc);
  for (uint32_t n = 0; n < count; ++n) {
    int32_t v[5] = {};
    Slot slot;
    for (int32_t& x : v) tr.get(x);
    tr.get(slot.offset);
    if (checksums) tr.get(slot.hash);
    slot.checked = checksums;
    slot.size = v[4];
    if (slot.size < 1 || slot.size > kMaxPageSize ||
        slot.offset + imageBytes(slot.size) > reader.file_size_)
      return Status::error(StatusCode::kCorrupt,
                           path + ": entry " + std::to_string(n) + " is corrupt");
    // A damaged key could name another RDM of the store: refuse the store, never alias.
    if (!reader.toc_.emplace(RdmKey{v[0], v[1], v[2], v[3]}, slot).second)
      return Status::error(StatusCode::kCorrupt,
                           path + ": entry " + std::to_string(n) + " repeats an RDM (damaged)");
  }
  return reader;
}

Expected<Image> RdmStoreReader::read(const RdmKey& key) const {
  auto it = toc_.find(key);
  if (it == toc_.end()) return Status::notFound(path_ + ": no such RDM");
  std::ifstream in(path_, std::ios::binary);
  in.seekg(std::streamoff(it->second.offset));
  Image image(2 * it->second.size, 3 * it->second.size, 4);
  in.read(reinterpret_cast<char*>(image.pixels.data()),
          std::streamsize(image.pixels.size() * sizeof(float)));
  if (!in) return Status::error(StatusCode::kCorrupt, path_ + ": cut short");
  const std::string_view bytes(reinterpret_cast<const char*>(image.pixels.data()),
                               image.pixels.size() * sizeof(float));
  if (const uint64_t actual = contentHash(bytes); it->second.checked && actual != it->second.hash) {
    const auto& [i, j, k, level] = key;
    // The store stays in place: its other RDMs are intact and each is checked on its own.
    logEvent(LogLevel::kError, "corrupt",
             {{"path", path_},
              {"rdm", {i, j, k, level}},
              {"expected", hex16(it->second.hash)},
              {"actual", hex16(actual)}});
    return Status::error(StatusCode::kCorrupt,
                         path_ + ": the texels of slot (" + std::to_string(i) + ", " +
                             std::to_string(j) + ", " + std::to_string(k) + ") level " +
                             std::to_string(level) +
                             " fail their checksum (the file is damaged); bake the job again");
  }
  return image;
}

}  // namespace rdm
