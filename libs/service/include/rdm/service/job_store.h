// A job's files in the data directory:
//   jobs/<id>/job.json         the record (atomic, fsync'd); a job exists once this exists
//   jobs/<id>/plan.json        RDMs the job bakes, in plan order (unit files index into it)
//   jobs/<id>/units.log        finished work units, one appended record each (unit_checkpoint.h)
//   jobs/<id>/out/             atlas.exr (atlas.page<N>.exr), index.json, index.txt
//   jobs/<id>/rdms.bin         per RDM of the result: origin job and slot sets
// The unit log skips fsync: an append that a SIGKILL or power cut tears fails its checksum
// on read, and that unit and the ones after it are baked again.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/status.h"
#include "rdm/service/job.h"

namespace rdm {

class JobStore {
 public:
  explicit JobStore(std::string data_dir) : dir_(std::move(data_dir) + "/jobs") {}
  Status init();
  std::vector<JobRecord> loadAll() const;

  std::string jobDir(const std::string& id) const { return dir_ + "/" + id; }
  std::string outDir(const std::string& id) const { return jobDir(id) + "/out"; }

  Status saveJob(const JobRecord& job) const;
  Status savePlan(const std::string& id, const std::vector<RdmId>& plan) const;
  std::optional<std::vector<RdmId>> loadPlan(const std::string& id) const;
  Status saveUnit(const std::string& id, const UnitResult& unit, int local_index) const;
  // Reads the unit log one unit at a time; returns how many units it held.
  size_t forEachUnit(const std::string& id, const std::function<void(UnitResult&)>& use) const;
  void removeUnits(const std::string& id) const;
  void removeOutputs(const std::string& id) const;  // a failed job's partial results
  Status saveRdmRecords(const std::string& id, const std::vector<RdmRecord>& records) const;
  std::optional<std::vector<RdmRecord>> loadRdmRecords(const std::string& id) const;
  size_t countUnitFiles(const std::string& id) const;  // units in the log
  // Deleting a job (DELETE /v1/jobs/{id}, retention): trashJob renames jobs/<id> to
  // jobs/.trash-<id> in one rename, so a crash leaves the job whole or gone (loadAll skips
  // the trash); emptyTrash removes what is there (init() sweeps a crash's leftovers).
  Status trashJob(const std::string& id) const;
  void emptyTrash() const;
  void removeTrashed(const std::string& id) const;  // the files trashJob(id) moved
  uint64_t jobBytes(const std::string& id) const;   // bytes of the job's files
  uint64_t dataBytes() const;                       // bytes of the whole data directory

 private:
  std::string dir_;
  mutable std::mutex append_mutex_;  // one append to a unit log at a time
};

}  // namespace rdm
