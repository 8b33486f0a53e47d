// Persistence of finished work units and of a job's per-RDM slot sets.
//
// A unit file (jobs/<id>/units/<rdm>.<unit>.bin) holds one work unit's texel rect: RGBZ and
// the standard error for each texel of face `face`, texels [x0, x1) x [y0, y1), plus the
// unit's slot sets. Restoring it writes exactly the floats the unit would compute, so a
// resumed bake is bit-identical to an uninterrupted one. Files carry a magic, the RDM id
// and an XXH3 checksum (rdm/base/hash.h); anything that does not check out is ignored and the unit
// re-runs.
#pragma once

#include <cstring>
#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/slot_set.h"

namespace rdm {

struct UnitResult {
  RdmId id;
  BakeUnit unit;  // unit.rdm is the index in the job's plan
  uint64_t rays = 0;
  double seconds = 0.0;
  std::vector<float> rgbz, err;  // row-major over the rect, 4 and 3 floats per texel
  std::vector<uint32_t> full_set, first_set;
  bool smooth = false;
};

// Copies the unit's rect out of `rdm` (image and stderr).
void extractUnit(const RdmData& rdm, const BakeUnit& unit, UnitResult& out);
// Writes the rect back into `rdm`; false when it does not fit.
bool applyUnit(const UnitResult& r, RdmData& rdm);

std::string encodeUnit(const UnitResult& r);
std::optional<UnitResult> decodeUnit(const std::string& bytes);

// A job's unit log (docs/spec.md section 8.10): every finished unit appended as one record,
// a little-endian u64 byte length then encodeUnit's bytes, so checkpointing a unit is one
// append instead of a file create and rename. Reading stops at the first record that is
// cut short or fails its checksum (a torn tail after a crash); those units run again.
std::string unitLogRecord(const UnitResult& r);
// Calls `use` with each unit of the log in turn (one held at a time); returns how many.
size_t forEachLoggedUnit(std::istream& log, const std::function<void(UnitResult&)>& use);
std::vector<UnitResult> readUnitLog(const std::string& bytes);
constexpr const char* kUnitLogFile = "units.log";  // in the job's directory

// Per RDM of a finished job: where its texels came from and its slot sets.
struct RdmRecord {
  RdmId id;
  std::string origin_job;  // the job that baked these texels (itself, or an ancestor)
  bool smooth = false;
  SlotSet full_set, first_set;
};

// rdms.bin: sets as SlotSet bytes ("RM RMDS2"); files of the previous format, with sets as
// u32 arrays ("RM RMDS1"), still read.
std::string encodeRdmRecords(const std::vector<RdmRecord>& records);
std::optional<std::vector<RdmRecord>> decodeRdmRecords(const std::string& bytes);
// The records file of a daemon job's directory and of an `rdm bake` output directory, sorted
// by rdmKey in the latter (docs/spec.md section 4).
constexpr const char* kRdmRecordsFile = "rdms.bin";

}  // namespace rdm
