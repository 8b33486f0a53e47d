// One bake on a Vulkan device that already has its pipelines (vulkan_context.h): scene
// upload, the plan (vulkan_bake_plan.h), batches of paths dispatched until none is active, and
// the per-texel estimators (double, in texel then sample order, as the CPU accumulates); a
// radiance map's texels go to its FaceMapBuilder, and a finished map is derived into its
// consumers' faces. With slot-set recording the kernel ORs the slots its walks enter into one
// full and one first-segment bitset per slot-set owner of the batch (rdm_gpu_layout.h), which
// the host reads back after each batch; central rays are recorded in the plan, on the host.
#if RDM_HAVE_VULKAN

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <utility>

#include "rdm/bake/bake_stats.h"
#include "rdm/bake/slot_set.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sobol.h"
#include "vulkan_bake_plan.h"
#include "vulkan_context.h"
#include "vulkan_kernel_run.h"
#include "vulkan_prefilter.h"

namespace rdm::vkbake {
namespace {

using glm::ivec3;
using glm::vec3;

// Appends the linear slot index of every set bit of `bits` (`count` words) to `out`.
void appendBits(const uint32_t* bits, uint32_t count, std::vector<uint32_t>& out) {
  for (uint32_t w = 0; w < count; ++w) {
    for (uint32_t b = bits[w]; b != 0; b &= b - 1)
      out.push_back(w * 32 + uint32_t(__builtin_ctz(b)));
  }
}

// A texel group being summed (an RDM texel, a level-7 face of S^2 jobs, or a map texel):
// its estimator, the samples each of its jobs took, and a map texel's cosine sums.
struct OpenGroup {
  int group = -1;  // index of its first job
  uint32_t samples = 0, sobol_key = 0;
  SampleEstimator estimator;
  CosineSums cosine;
};

// Target-error sampling (BakeOptions::target_error): a group under the target, or at the
// cap, is finished; another doubles its samples, as the CPU's FaceBaker::refine does.
struct RefinePolicy {
  double target_error = 0.0;
  uint32_t cap = 0;  // spp * max_spp_factor
  bool needsMore(const OpenGroup& g) const {
    return target_error > 0.0 && g.samples < cap && !(g.estimator.relativeError() < target_error);
  }
  uint32_t next(const OpenGroup& g) const { return std::min(cap, 2 * g.samples); }
};

// Takes each batch's results in job, then sample order (the CPU's order): an RDM texel
// group's estimate into its RDM, a map texel's into its map's builder; a finished map goes to
// the prefilter pass, which derives its consumers' faces. A group that needs more samples
// waits in refining() until the driver traced them (addTo) and settle() decides again.
class ResultSink {
 public:
  // `work_done(r, n)`: n of RDM r's pending texel jobs or map faces are finished.
  ResultSink(const BakeSettings& settings, const RefinePolicy& refine, BakePlan& plan,
             BakeResult& result, DevicePrefilter& prefilter,
             std::function<void(int, int)> work_done)
      : seed_(settings.seed),
        refine_(refine),
        plan_(plan),
        result_(result),
        prefilter_(prefilter),
        work_done_(std::move(work_done)) {}
  // The first device error of the prefilter pass, if any.
  const Status& status() const { return status_; }

  // Samples [first_sample, first_sample + count) of job `index`.
  void add(size_t index, uint32_t first_sample, const glm::vec4* values, uint32_t count) {
    const Job& job = plan_.jobs[index];
    if (job.group != open_.group) {
      finishGroup();
      open_.group = job.group;
      if (job.map >= 0) {
        const int S = plan_.maps[size_t(job.map)].size;
        const uint32_t texel = uint32_t(job.face * S * S + job.j * S + job.i);
        open_.sobol_key = shared::pathKey(seed_, job.gpu.data.x, 0u, texel, 0u);
      }
    }
    addTo(open_, job, first_sample, values, count);
    open_.samples = first_sample + count;
  }

  // Samples [first_sample, first_sample + count) of `job`, a job of group `g`; the caller
  // sets g.samples once every job of the group has them.
  void addTo(OpenGroup& g, const Job& job, uint32_t first_sample, const glm::vec4* values,
             uint32_t count) {
    for (uint32_t s = 0; s < count; ++s) {
      const glm::vec4 v = values[s];
      checkPathResult(v);
      g.estimator.add(vec3(v), v.w);
      if (job.map >= 0) {
        const glm::vec2 p = shared::owenSobolPoint(first_sample + s, g.sobol_key);
        const int S = plan_.maps[size_t(job.map)].size;
        g.cosine.add(shared::texelFootprintPoint(job.i, job.j, S, p.x, p.y), vec3(v));
      }
    }
  }

  void finishGroup() {
    if (open_.group < 0) return;
    settle(std::move(open_));
    open_ = OpenGroup();
  }

  // Groups waiting for samples [samples, RefinePolicy::next(g)) of each of their jobs.
  std::vector<OpenGroup> takeRefining() { return std::exchange(refining_, {}); }
  // Finishes `g`, or queues it for more samples.
  void settle(OpenGroup&& g) {
    if (refine_.needsMore(g)) {
      refining_.push_back(std::move(g));
      return;
    }
    const Job& first = plan_.jobs[size_t(g.group)];
    if (first.map >= 0) {
      finishMapTexel(first, g);
    } else {
      finishRdmGroup(first, g);
    }
  }

 private:
  void finishRdmGroup(const Job& first, const OpenGroup& g) {
    RdmData& rdm = result_.rdms[size_t(first.rdm)];
    const int S = rdm.id.size;
    const size_t count = rdm.id.level == shared::kDiffuseLevel ? size_t(S) * S : 1;
    const glm::dvec3 mean = g.estimator.mean(), err = g.estimator.stderror();
    for (size_t n = 0; n < count; ++n) {
      const Job& job = plan_.jobs[size_t(g.group) + n];
      storeRadiance(rdm, job.face, job.i, job.j, mean, err);
    }
    rdm.max_samples = std::max(rdm.max_samples, g.samples);
    work_done_(first.rdm, int(count));
  }

  void finishMapTexel(const Job& job, const OpenGroup& g) {
    PlannedMap& map = plan_.maps[size_t(job.map)];
    map.builder->setTexel(job.i, job.j, g.estimator, g.samples, g.cosine);
    for (int c : map.consumers) {
      uint32_t& m = result_.rdms[size_t(c)].max_samples;
      m = std::max(m, g.samples);
    }
    if (--map.jobs_left > 0) return;
    FaceMap finished;
    map.builder->finish(finished);
    map.builder.reset();
    Status s = prefilter_.derive(std::move(finished), map.face, map.consumers, result_.rdms);
    if (!s && status_.ok()) status_ = s;
  }

  const uint32_t seed_;
  const RefinePolicy refine_;
  BakePlan& plan_;
  BakeResult& result_;
  DevicePrefilter& prefilter_;
  const std::function<void(int, int)> work_done_;
  Status status_;
  OpenGroup open_;
  std::vector<OpenGroup> refining_;
};

// The jobs of group `g`: [g.group, end).
size_t groupEnd(const std::vector<Job>& jobs, const OpenGroup& g) {
  size_t end = size_t(g.group);
  while (end < jobs.size() && jobs[end].group == g.group) ++end;
  return end;
}

}  // namespace

Expected<BakeResult> bakeOnContext(Context& ctx, const VulkanDeviceInfo& device,
                                   const VoxelWorld& world, const BakeSettings& settings,
                                   const std::vector<RdmId>& rdms,
                                   const VulkanBakeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  BakeResult result;
  BakeReport& report = result.report;
  report.effects = sceneEffects(world);
  const bool sun = report.effects.sun || options.all_effects;
  const bool emit = report.effects.emitters || options.all_effects;
  const bool record = options.record_slot_sets;
  BakePlan plan = planBake(world, settings, rdms, result);
  KernelConfig config;
  config.sun = sun, config.emitters = emit, config.record = record;
  config.spp = uint32_t(settings.spp);
  config.set_owners = plan.owners.size();
  config.max_batch_paths = options.max_batch_paths;
  config.loop_budget = options.loop_budget;
  config.max_dispatch_seconds = options.max_dispatch_seconds;
  auto created = KernelRun::create(ctx, world, settings, config);
  if (!created) return created.status();
  KernelRun& kernel = **created;
  Buffers buffers(ctx);  // the prefilter pass's

  VulkanBakeInfo info;
  info.device = device;
  info.setup_seconds = elapsed();

  // An RDM is complete once its texel jobs or map faces are: its sets are merged and sorted,
  // and a streaming bake hands it out and frees it.
  RdmTexels texels(world, record, result.rdms.size());
  std::vector<RdmErrorStats> errors(result.rdms.size());
  int rdms_done = 0;
  auto complete = [&](size_t r) {
    RdmData& rdm = result.rdms[r];
    texels.ensure(rdm, r);  // every face skipped: no job allocated it
    if (record && plan.maps_owner[r] >= 0) {
      const OwnerSets& maps = plan.owners[size_t(plan.maps_owner[r])];
      rdm.full_set.insert(rdm.full_set.end(), maps.full.begin(), maps.full.end());
      rdm.first_set.insert(rdm.first_set.end(), maps.first.begin(), maps.first.end());
      rdm.smooth_vertex = rdm.smooth_vertex || maps.smooth;
    }
    sortUniqueSlots(rdm.full_set), sortUniqueSlots(rdm.first_set);
    errors[r] = rdmErrorStats(rdm);
    ++rdms_done;
    if (options.on_rdm_done) options.on_rdm_done(rdm), texels.release(rdm);
  };
  auto work_done = [&](int r, int count) {
    if ((plan.pending[size_t(r)] -= count) == 0) complete(size_t(r));
  };
  DevicePrefilter prefilter(ctx, buffers, options.max_prefilter_texels,
                            [&](int r) { work_done(r, 1); });
  if (Status s = prefilter.prepare(plan, result.rdms); !s) return s;
  RefinePolicy refine;
  refine.target_error = options.target_error;
  refine.cap = uint32_t(settings.spp) * uint32_t(std::max(1, options.max_spp_factor));
  ResultSink sink(settings, refine, plan, result, prefilter, work_done);
  for (size_t r = 0; r < result.rdms.size(); ++r)
    if (plan.pending[r] == 0) complete(r);
  // The batch's sets into its owners o0..o1 (batch-local 0..o1 - o0); the words are cleared.
  auto collectSets = [&](int o0, int o1) {
    uint32_t* words = kernel.slotSets();
    const uint32_t set_words = kernel.setWords();
    for (int o = o0; o <= o1; ++o) {
      const uint32_t* w = words + size_t(o - o0) * (2 * size_t(set_words) + 1);
      OwnerSets& owner = plan.owners[size_t(o)];
      RdmData* rdm = owner.rdm >= 0 ? &result.rdms[size_t(owner.rdm)] : nullptr;
      appendBits(w, set_words, rdm ? rdm->full_set : owner.full);
      appendBits(w + set_words, set_words, rdm ? rdm->first_set : owner.first);
      bool& smooth = rdm ? rdm->smooth_vertex : owner.smooth;
      smooth = smooth || w[2 * size_t(set_words)] != 0;
    }
    std::memset(words, 0, size_t(o1 - o0 + 1) * kernel.ownerSetBytes());
  };

  const std::vector<Job>& jobs = plan.jobs;
  bool cancelled = false;
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done, int(result.rdms.size()), kernel.rays(), elapsed()});
  };
  auto setJob = [&](uint32_t n, size_t index, int o0) {
    gpu::GpuJob g = jobs[index].gpu;
    g.data.w = uint32_t(jobs[index].owner - o0);
    kernel.jobs()[n] = g;
  };
  // Target-error rounds: every waiting group's jobs take samples [n, next(n)), in batches
  // of one round's groups (a round shares n), until every group is settled. False: cancelled.
  auto refineGroups = [&]() -> Expected<bool> {
    for (std::vector<OpenGroup> round = sink.takeRefining(); !round.empty();
         round = sink.takeRefining()) {
      std::vector<std::pair<size_t, size_t>> work;  // (group in round, job)
      for (size_t g = 0; g < round.size(); ++g)
        for (size_t j = size_t(round[g].group); j < groupEnd(jobs, round[g]); ++j)
          work.emplace_back(g, j);
      for (size_t w0 = 0; w0 < work.size();) {
        const OpenGroup& lead = round[work[w0].first];
        const uint32_t first = lead.samples, samples = refine.next(lead) - first;
        const uint32_t chunk = uint32_t(std::min<uint64_t>(samples, kernel.batchPaths()));
        uint32_t nj = uint32_t(
            std::min<uint64_t>({kernel.maxJobs(), kernel.batchPaths() / chunk, work.size() - w0}));
        const int o0 = jobs[work[w0].second].owner;
        uint32_t n = 0;
        for (; n < nj; ++n) {
          const OpenGroup& g = round[work[w0 + n].first];
          const Job& job = jobs[work[w0 + n].second];
          if (g.samples != first || (record && uint64_t(job.owner - o0) >= kernel.setOwners()))
            break;
          setJob(n, work[w0 + n].second, o0);
        }
        nj = n;
        for (uint32_t s = first; s < first + samples; s += chunk) {
          const uint32_t ns = std::min(chunk, first + samples - s);
          auto ran = kernel.runBatch(nj, ns, s, options.cancel, progress);
          if (!ran) return ran.status();
          if (!*ran) return false;
          if (record) collectSets(o0, jobs[work[w0 + nj - 1].second].owner);
          for (uint32_t k = 0; k < nj; ++k)
            sink.addTo(round[work[w0 + k].first], jobs[work[w0 + k].second], s,
                       kernel.results() + size_t(k) * ns, ns);
        }
        w0 += nj;
      }
      for (OpenGroup& g : round) {
        g.samples = refine.next(g);
        sink.settle(std::move(g));
      }
      if (!sink.status()) return sink.status();
      if (Status st = prefilter.flush(result.rdms); !st) return st;
      progress();
    }
    return true;
  };
  size_t j0 = 0;
  uint32_t s0 = 0;
  while (j0 < jobs.size() && !cancelled) {
    uint32_t nj = uint32_t(std::min<size_t>(kernel.maxJobs(), jobs.size() - j0));
    const int o0 = jobs[j0].owner;
    if (record) {  // at most setOwners() owners: jobs are in owner order
      const auto first = jobs.begin() + std::ptrdiff_t(j0);
      nj = uint32_t(std::partition_point(
                        first, first + nj,
                        [&](const Job& j) { return uint64_t(j.owner - o0) < kernel.setOwners(); }) -
                    first);
    }
    const uint32_t ns = kernel.samplesFrom(s0);
    for (uint32_t n = 0; n < nj; ++n) {
      const Job& job = jobs[j0 + n];
      if (job.rdm >= 0) texels.ensure(result.rdms[size_t(job.rdm)], size_t(job.rdm));
      if (job.map >= 0 && !plan.maps[size_t(job.map)].started) {
        plan.maps[size_t(job.map)].started = true;
        for (int c : plan.maps[size_t(job.map)].consumers)
          texels.ensure(result.rdms[size_t(c)], size_t(c));
      }
      setJob(n, j0 + n, o0);
    }
    auto ran = kernel.runBatch(nj, ns, s0, options.cancel, progress);
    if (!ran) return ran.status();
    cancelled = !*ran;
    if (cancelled) break;
    if (record) collectSets(o0, jobs[j0 + nj - 1].owner);
    for (uint32_t n = 0; n < nj; ++n) sink.add(j0 + n, s0, kernel.results() + size_t(n) * ns, ns);
    if (!sink.status()) return sink.status();
    // The maps this batch finished, derived now, so their RDMs leave with this batch.
    if (Status s = prefilter.flush(result.rdms); !s) return s;
    s0 += ns;
    if (s0 >= uint32_t(settings.spp)) s0 = 0, j0 += nj;
    if (s0 == 0) {  // the groups this batch finished that need more samples
      auto refined = refineGroups();
      if (!refined) return refined.status();
      cancelled = !*refined;
    }
    progress();
  }
  if (!cancelled) {
    sink.finishGroup();
    if (!sink.status()) return sink.status();
    auto refined = refineGroups();
    if (!refined) return refined.status();
    cancelled = !*refined;
  }
  if (!cancelled) {
    if (Status s = prefilter.flush(result.rdms); !s) return s;
  }

  kernel.addStats(info);
  info.prefilter_dispatches = prefilter.dispatches();
  info.texels_prefiltered = prefilter.texelsDerived();
  info.prefilter_seconds = prefilter.seconds();
  report.rdms = int(result.rdms.size());
  report.rays = kernel.rays();
  report.cancelled = cancelled;
  report.seconds = elapsed();
  for (size_t r = 0; r < result.rdms.size(); ++r) {  // a cancelled bake's unfinished RDMs
    if (plan.pending[r] != 0 && !result.rdms[r].image.pixels.empty())
      errors[r] = rdmErrorStats(result.rdms[r]);
  }
  summariseBake(errors, report);
  report.peak_rdms_held = texels.peakHeld();
  if (options.info) *options.info = info;
  return result;
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
