#include "rdm/bake/unit_checkpoint.h"

#include <algorithm>
#include <functional>
#include <sstream>

#include "rdm/base/binary_io.h"
#include "rdm/base/hash.h"

namespace rdm {
namespace {

constexpr uint64_t kUnitMagic = 0x31544e55204d4452ull;      // "RDM UNT1"
constexpr uint64_t kRecordMagicV1 = 0x3153444d52204d52ull;  // "RM RMDS1": u32 arrays
constexpr uint64_t kRecordMagic = 0x3253444d52204d52ull;    // "RM RMDS2": SlotSet bytes
constexpr uint64_t kMaxSet = 1ull << 24;                    // 256^3 slots
// A unit's record: at most a 4096 x 4096 rect (28 bytes per texel) and two full sets.
constexpr uint64_t kMaxUnitBytes = (uint64_t(4096) * 4096 * 28) + 8 * kMaxSet + 4096;
constexpr uint64_t kMaxTexels = 64 * 64;

void putId(BinaryWriter& w, const RdmId& id) {
  w.put(id.slot.x), w.put(id.slot.y), w.put(id.slot.z), w.put(id.level), w.put(id.size);
}
bool getId(BinaryReader& r, RdmId& id) {
  return r.get(id.slot.x) && r.get(id.slot.y) && r.get(id.slot.z) && r.get(id.level) &&
         r.get(id.size);
}

// Appends the checksum of everything so far; checkSum verifies and strips it.
std::string sealed(BinaryWriter& w) {
  uint64_t h = contentHash(w.bytes());
  w.put(h);
  return std::move(w.bytes());
}
bool checkSum(const std::string& bytes) {
  if (bytes.size() < 8) return false;
  uint64_t h = 0;
  std::memcpy(&h, bytes.data() + bytes.size() - 8, 8);
  return h == contentHash(std::string_view(bytes).substr(0, bytes.size() - 8));
}

template <class Fn>
void forEachTexel(const RdmId& id, const BakeUnit& u, Fn fn) {
  const int S = id.size;
  size_t t = 0;
  for (int j = u.y0; j < u.y1; ++j)
    for (int i = u.x0; i < u.x1; ++i, ++t) fn(S * (u.face % 2) + i, S * (u.face / 2) + j, t);
}

}  // namespace

void extractUnit(const RdmData& rdm, const BakeUnit& u, UnitResult& out) {
  out.id = rdm.id;
  out.unit = u;
  const size_t n = size_t(u.x1 - u.x0) * size_t(u.y1 - u.y0);
  out.rgbz.resize(n * 4);
  out.err.resize(n * 3);
  forEachTexel(rdm.id, u, [&](int x, int y, size_t t) {
    const size_t p = size_t(y) * rdm.image.width + x;
    for (int c = 0; c < 4; ++c) out.rgbz[t * 4 + c] = rdm.image.pixels[p * 4 + c];
    for (int c = 0; c < 3; ++c) out.err[t * 3 + c] = rdm.stderr_rgb[p * 3 + c];
  });
}

bool applyUnit(const UnitResult& r, RdmData& rdm) {
  const BakeUnit& u = r.unit;
  const int S = rdm.id.size;
  const size_t n = size_t(u.x1 - u.x0) * size_t(u.y1 - u.y0);
  if (!(r.id == rdm.id) || u.face < 0 || u.face > 5 || u.x0 < 0 || u.y0 < 0 || u.x1 > S ||
      u.y1 > S || u.x0 >= u.x1 || u.y0 >= u.y1 || r.rgbz.size() != n * 4 || r.err.size() != n * 3) {
    return false;
  }
  forEachTexel(rdm.id, u, [&](int x, int y, size_t t) {
    const size_t p = size_t(y) * rdm.image.width + x;
    for (int c = 0; c < 4; ++c) rdm.image.pixels[p * 4 + c] = r.rgbz[t * 4 + c];
    for (int c = 0; c < 3; ++c) rdm.stderr_rgb[p * 3 + c] = r.err[t * 3 + c];
  });
  return true;
}

std::string encodeUnit(const UnitResult& r) {
  BinaryWriter w;
  w.put(kUnitMagic);
  putId(w, r.id);
  const BakeUnit& u = r.unit;
  w.put(u.rdm), w.put(u.face), w.put(u.x0), w.put(u.y0), w.put(u.x1), w.put(u.y1);
  w.put(r.rays), w.put(r.seconds), w.put(uint8_t(r.smooth));
  w.putArray(r.rgbz), w.putArray(r.err), w.putArray(r.full_set), w.putArray(r.first_set);
  return sealed(w);
}

std::optional<UnitResult> decodeUnit(const std::string& bytes) {
  if (!checkSum(bytes)) return std::nullopt;
  const std::string body = bytes.substr(0, bytes.size() - 8);
  BinaryReader rd(body);
  UnitResult r;
  uint64_t magic = 0;
  uint8_t smooth = 0;
  BakeUnit& u = r.unit;
  bool ok = rd.get(magic) && magic == kUnitMagic && getId(rd, r.id) && rd.get(u.rdm) &&
            rd.get(u.face) && rd.get(u.x0) && rd.get(u.y0) && rd.get(u.x1) && rd.get(u.y1) &&
            rd.get(r.rays) && rd.get(r.seconds) && rd.get(smooth) &&
            rd.getArray(r.rgbz, kMaxTexels * 4) && rd.getArray(r.err, kMaxTexels * 3) &&
            rd.getArray(r.full_set, kMaxSet) && rd.getArray(r.first_set, kMaxSet) && rd.atEnd();
  if (!ok) return std::nullopt;
  r.smooth = smooth != 0;
  return r;
}

std::string encodeRdmRecords(const std::vector<RdmRecord>& records) {
  BinaryWriter w;
  w.put(kRecordMagic);
  w.put(uint64_t(records.size()));
  for (const RdmRecord& r : records) {
    putId(w, r.id);
    w.putString(r.origin_job);
    w.put(uint8_t(r.smooth));
    w.putString(r.full_set.bytes()), w.putString(r.first_set.bytes());
  }
  return sealed(w);
}

namespace {

bool getSlotSet(BinaryReader& rd, bool arrays, SlotSet& set) {
  if (arrays) {
    std::vector<uint32_t> v;
    if (!rd.getArray(v, kMaxSet) ||
        std::adjacent_find(v.begin(), v.end(), std::greater_equal<uint32_t>()) != v.end())
      return false;
    set = SlotSet::fromSorted(v);
    return true;
  }
  std::string bytes;
  if (!rd.getString(bytes, 5 * 2 * kMaxSet)) return false;
  auto parsed = SlotSet::fromBytes(std::move(bytes), kMaxSet);
  if (!parsed) return false;
  set = std::move(*parsed);
  return true;
}

}  // namespace

std::optional<std::vector<RdmRecord>> decodeRdmRecords(const std::string& bytes) {
  if (!checkSum(bytes)) return std::nullopt;
  const std::string body = bytes.substr(0, bytes.size() - 8);
  BinaryReader rd(body);
  uint64_t magic = 0, count = 0;
  if (!rd.get(magic) || (magic != kRecordMagic && magic != kRecordMagicV1) || !rd.get(count) ||
      count > kMaxSet)
    return std::nullopt;
  const bool arrays = magic == kRecordMagicV1;
  std::vector<RdmRecord> out(static_cast<size_t>(count));
  for (RdmRecord& r : out) {
    uint8_t smooth = 0;
    if (!(getId(rd, r.id) && rd.getString(r.origin_job, 64) && rd.get(smooth) &&
          getSlotSet(rd, arrays, r.full_set) && getSlotSet(rd, arrays, r.first_set))) {
      return std::nullopt;
    }
    r.smooth = smooth != 0;
  }
  if (!rd.atEnd()) return std::nullopt;
  return out;
}

std::string unitLogRecord(const UnitResult& r) {
  const std::string body = encodeUnit(r);
  const uint64_t length = body.size();
  std::string out(reinterpret_cast<const char*>(&length), sizeof(length));
  return out + body;
}

size_t forEachLoggedUnit(std::istream& log, const std::function<void(UnitResult&)>& use) {
  size_t count = 0;
  std::string body;
  uint64_t length = 0;
  while (log.read(reinterpret_cast<char*>(&length), sizeof(length))) {
    if (length > kMaxUnitBytes) break;
    body.resize(size_t(length));
    if (!log.read(body.data(), std::streamsize(length))) break;
    auto unit = decodeUnit(body);
    if (!unit) break;
    use(*unit);
    ++count;
  }
  return count;
}

std::vector<UnitResult> readUnitLog(const std::string& bytes) {
  std::vector<UnitResult> out;
  std::istringstream log(bytes);
  forEachLoggedUnit(log, [&](UnitResult& r) { out.push_back(std::move(r)); });
  return out;
}

}  // namespace rdm
