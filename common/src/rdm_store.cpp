#include "rdm/rdm_store.h"

#include <cstring>
#include <fstream>

#include "binary_io.h"
#include "rdm/file_util.h"

namespace rdm {
namespace {

constexpr uint64_t kStoreMagic = 0x31524f54534d4452ull;  // "RDMSTOR1"
constexpr uint32_t kMaxEntries = 1u << 24;
constexpr size_t kEntryBytes = 5 * sizeof(int32_t) + sizeof(uint64_t);

uint64_t imageBytes(int size) {
  return uint64_t(2 * size) * uint64_t(3 * size) * 4 * sizeof(float);
}

}  // namespace

Status writeRdmStore(const std::string& path, const RdmSource& rdms) {
  const std::vector<RdmId> ids = rdms.ids();
  BinaryWriter w;
  w.put(kStoreMagic);
  w.put(uint32_t(ids.size()));
  std::vector<uint64_t> offsets;
  uint64_t offset = sizeof(uint64_t) + sizeof(uint32_t) + ids.size() * kEntryBytes;
  for (const RdmId& id : ids) {
    w.put(int32_t(id.slot.x)), w.put(int32_t(id.slot.y)), w.put(int32_t(id.slot.z));
    w.put(int32_t(id.level)), w.put(int32_t(id.size)), w.put(offset);
    offsets.push_back(offset);
    offset += imageBytes(id.size);
  }
  auto file = AtomicFileWriter::create(path);
  if (!file) return file.status();
  (*file)->writeAt(0, w.bytes().data(), w.bytes().size());
  for (size_t i = 0; i < ids.size(); ++i) {
    const Status read = rdms.visit(i, [&](const RdmData& r) {
      RDM_CHECK(r.image.pixels.size() * sizeof(float) == imageBytes(r.id.size));
      (*file)->writeAt(offsets[i], reinterpret_cast<const char*>(r.image.pixels.data()),
                       r.image.pixels.size() * sizeof(float));
    });
    if (!read) return read;
  }
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
  if (!in || !hr.get(magic) || !hr.get(count) || magic != kStoreMagic || count > kMaxEntries)
    return Status::error(StatusCode::kIo, path + ": not a per-RDM store");
  std::string toc(size_t(count) * kEntryBytes, '\0');
  in.read(toc.data(), std::streamsize(toc.size()));
  if (!in) return Status::error(StatusCode::kIo, path + ": table of contents cut short");
  BinaryReader tr(toc);
  for (uint32_t n = 0; n < count; ++n) {
    int32_t v[5] = {};
    Slot slot;
    for (int32_t& x : v) tr.get(x);
    tr.get(slot.offset);
    slot.size = v[4];
    if (slot.size < 1 || slot.size > kMaxPageSize ||
        slot.offset + imageBytes(slot.size) > reader.file_size_)
      return Status::error(StatusCode::kIo, path + ": entry " + std::to_string(n) + " is corrupt");
    reader.toc_[{v[0], v[1], v[2], v[3]}] = slot;
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
  if (!in) return Status::error(StatusCode::kIo, path_ + ": cut short");
  return image;
}

}  // namespace rdm
