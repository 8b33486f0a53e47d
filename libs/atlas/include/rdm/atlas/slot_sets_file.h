// rdms.bin of an `rdm bake` output directory (docs/spec.md section 4): every RDM's slot sets,
// so that an in-process rebake can start from the atlas instead of baking everything again.
// The same records as a daemon job's rdms.bin (encodeRdmRecords), sorted by rdmKey.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/rdm_list.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/status.h"

namespace rdm {

RdmRecord recordOf(const RdmData& rdm, std::string origin_job);

// Writes `records` sorted by rdmKey to DIR/rdms.bin, atomically.
Status writeSlotSetsFile(const std::string& dir, std::vector<RdmRecord> records);

// DIR/rdms.bin by RDM; kNotFound when the file is missing.
Expected<std::map<RdmKey, RdmRecord>> readSlotSetsFile(const std::string& dir);

}  // namespace rdm
