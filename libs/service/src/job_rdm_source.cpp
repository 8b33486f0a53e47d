#include "job_rdm_source.h"

#include "rdm/service/job_store.h"

namespace rdm {

Expected<std::unique_ptr<JobRdmSource>> JobRdmSource::open(const RdmSource& own,
                                                           const std::vector<RdmId>& plan,
                                                           const JobStore* copies,
                                                           const AtlasView& view,
                                                           const std::string& self) {
  std::unique_ptr<JobRdmSource> source(new JobRdmSource(own));
  std::map<RdmKey, size_t> index;
  const std::vector<RdmId> own_ids = own.ids();
  for (size_t i = 0; i < own_ids.size(); ++i) index[rdmKey(own_ids[i])] = i;
  for (const RdmId& id : plan) {
    auto it = index.find(rdmKey(id));
    if (it == index.end()) return Status::error("a planned RDM is missing from the job's spill");
    source->own_order_.push_back(it->second);
  }
  if (!copies) return source;
  for (const AtlasEntry& e : view.layout.entries) {
    const std::string& origin = view.origin.at(rdmKey(e.id));
    if (origin == self) continue;
    if (!source->readers_.count(origin)) {
      auto reader = RdmStoreReader::open(copies->outDir(origin) + "/" + kRdmStoreFile);
      if (!reader) return reader.status();
      source->readers_.emplace(origin, std::move(*reader));
    }
    source->copied_.push_back({e.id, origin});
  }
  return source;
}

std::vector<RdmId> JobRdmSource::ids() const {
  const std::vector<RdmId> own_ids = own_.ids();
  std::vector<RdmId> out;
  for (size_t i : own_order_) out.push_back(own_ids[i]);
  for (const Copied& c : copied_) out.push_back(c.id);
  return out;
}

Expected<std::vector<RdmDigest>> JobRdmSource::digests() const {
  auto own = own_.digests();
  if (!own) return own.status();
  std::vector<RdmDigest> out;
  for (size_t i : own_order_) out.push_back((*own)[i]);
  for (size_t i = own_order_.size(); i < own_order_.size() + copied_.size(); ++i) {
    const Status read = visit(i, [&](const RdmData& rdm) { out.push_back(digestRdm(rdm)); });
    if (!read) return read;
  }
  return out;
}

Status JobRdmSource::visit(size_t i, const std::function<void(const RdmData&)>& use) const {
  if (i < own_order_.size()) return own_.visit(own_order_[i], use);
  const Copied& c = copied_.at(i - own_order_.size());
  auto image = readers_.at(c.origin).read(rdmKey(c.id));
  if (!image) return image.status();
  RdmData rdm;
  rdm.id = c.id;
  rdm.image = std::move(*image);
  use(rdm);
  return {};
}

}  // namespace rdm
