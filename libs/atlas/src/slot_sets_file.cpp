#include "rdm/atlas/slot_sets_file.h"

#include <algorithm>
#include <filesystem>

#include "rdm/base/file_util.h"

namespace rdm {

RdmRecord recordOf(const RdmData& rdm, std::string origin_job) {
  return {rdm.id, std::move(origin_job), rdm.smooth_vertex, SlotSet::fromSorted(rdm.full_set),
          SlotSet::fromSorted(rdm.first_set)};
}

Status writeSlotSetsFile(const std::string& dir, std::vector<RdmRecord> records) {
  std::sort(records.begin(), records.end(),
            [](const RdmRecord& a, const RdmRecord& b) { return rdmKey(a.id) < rdmKey(b.id); });
  return writeFileAtomic(dir + "/" + kRdmRecordsFile, encodeRdmRecords(records));
}

Expected<std::map<RdmKey, RdmRecord>> readSlotSetsFile(const std::string& dir) {
  const std::string path = dir + "/" + kRdmRecordsFile;
  if (std::error_code ec; !std::filesystem::exists(path, ec))
    return Status::notFound(
        path + " is missing (atlases baked before 2026-12-06 have no slot sets)", kRdmRecordsFile);
  auto bytes = readFileToString(path);
  if (!bytes) return bytes.status();
  auto records = decodeRdmRecords(*bytes);
  if (!records) return Status::invalid(kRdmRecordsFile, path + " is corrupt or cut short");
  std::map<RdmKey, RdmRecord> out;
  for (RdmRecord& r : *records) out[rdmKey(r.id)] = std::move(r);
  return out;
}

}  // namespace rdm
