// The RDMs of a daemon job's result as its writers read them, one at a time: those the job
// baked, from its spill file in plan order (so that its files do not depend on the order in
// which units finished), then those it copies from earlier jobs, from their per-RDM stores
// (docs/spec.md section 8.10).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/atlas/rdm_store.h"
#include "rdm/bake/rdm_source.h"

namespace rdm {

class JobStore;

class JobRdmSource final : public RdmSource {
 public:
  // `own` (the job's spill, holding every RDM of `plan`) must outlive the source. With
  // `copies`, opens the per-RDM store of every origin of `view` other than `self`.
  static Expected<std::unique_ptr<JobRdmSource>> open(const RdmSource& own,
                                                      const std::vector<RdmId>& plan,
                                                      const JobStore* copies, const AtlasView& view,
                                                      const std::string& self);

  std::vector<RdmId> ids() const override;
  Expected<std::vector<RdmDigest>> digests() const override;
  Status visit(size_t i, const std::function<void(const RdmData&)>& use) const override;

 private:
  struct Copied {
    RdmId id;
    std::string origin;
  };
  explicit JobRdmSource(const RdmSource& own) : own_(own) {}

  const RdmSource& own_;
  std::vector<size_t> own_order_;  // plan index -> index in `own`
  std::vector<Copied> copied_;
  std::map<std::string, RdmStoreReader> readers_;
};

}  // namespace rdm
