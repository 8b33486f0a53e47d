// The denoiser on Vulkan compute (rdm/vulkan/vulkan_denoise.h, shaders/denoise.comp): a batch's
// faces in bands of output texels, one dispatch each; per band, every source face once
// (binding 0), the tasks (1), the results (2) and the parameters (3).
#include "rdm/vulkan/vulkan_denoise.h"

#include <chrono>
#include <cstring>
#include <map>
#include <utility>

#if RDM_HAVE_VULKAN
#include "vulkan_compute_program.h"
#endif

namespace rdm {

#if !RDM_HAVE_VULKAN

struct VulkanDenoiser::Impl {
  VulkanDeviceInfo device;
  VulkanDenoiseInfo info;
};
Expected<std::unique_ptr<VulkanDenoiser>> VulkanDenoiser::create(const std::string&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
Status VulkanDenoiser::denoise(const std::vector<DenoiseInput>&, const DenoiseSettings&,
                               std::vector<RdmData>&, DenoiseStats&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}

#else

using namespace vkbake;
using shared::DenoiseTexel;

namespace {

// Output texels per dispatch: 4,096 workgroups, a few source faces each, tens of MB.
constexpr uint32_t kBandTexels = 1u << 18;

// shaders/denoise.comp's DenoiseTask (std430).
struct GpuDenoiseTask {
  glm::uvec4 sources;  // first texel of source faces 0..3
  glm::uvec4 info;     // x: source 4, y: sources, z: S | window << 12 | radius << 20, w: output
};
static_assert(sizeof(GpuDenoiseTask) == 32 && sizeof(DenoiseTexel) == 48 &&
              sizeof(shared::DenoiseParams) == 16);

struct FaceJob {
  size_t rdm;
  int face;
  GpuDenoiseTask task;
};

}  // namespace

struct VulkanDenoiser::Impl {
  ComputeProgram program;
  const VulkanDeviceInfo& device{program.device};
  Buffer *faces = nullptr, *tasks = nullptr, *results = nullptr, *params = nullptr;
  VulkanDenoiseInfo info;

  // A band being gathered: its source faces (each (RDM, face) once) and filtered faces.
  std::vector<DenoiseTexel> texels;
  std::map<std::pair<const RdmData*, int>, uint32_t> source_of;
  std::vector<FaceJob> jobs;
  uint32_t output_texels = 0;

  uint32_t source(const RdmData& rdm, int face) {
    auto [it, fresh] = source_of.try_emplace({&rdm, face}, uint32_t(texels.size()));
    if (fresh) {
      const std::vector<DenoiseTexel> face_texels = denoiseFaceTexels(rdm, face);
      texels.insert(texels.end(), face_texels.begin(), face_texels.end());
    }
    return it->second;
  }
  Status flush(const DenoiseSettings& settings, std::vector<RdmData>& out, DenoiseStats& stats);
};

Status VulkanDenoiser::Impl::flush(const DenoiseSettings& settings, std::vector<RdmData>& out,
                                   DenoiseStats& stats) {
  if (jobs.empty()) return {};
  ComputeProgram& p = program;
  if (Status s = p.ensure(faces, texels.size() * sizeof(DenoiseTexel), "denoise face"); !s)
    return s;
  if (Status s = p.ensure(tasks, jobs.size() * sizeof(GpuDenoiseTask), "denoise task"); !s)
    return s;
  if (Status s = p.ensure(results, uint64_t(output_texels) * sizeof(DenoiseTexel), "denoised"); !s)
    return s;
  if (Status s = p.ensure(params, sizeof(shared::DenoiseParams), "denoise parameter"); !s) return s;
  std::memcpy(faces->mapped, texels.data(), texels.size() * sizeof(DenoiseTexel));
  auto* task = static_cast<GpuDenoiseTask*>(tasks->mapped);
  for (size_t k = 0; k < jobs.size(); ++k) task[k] = jobs[k].task;
  const shared::DenoiseParams parameters = denoiseParams(settings);
  std::memcpy(params->mapped, &parameters, sizeof(parameters));
  p.ctx.bind({faces, tasks, results, params}, p.ctx.descriptor_set);
  RDM_CHECK((output_texels + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize <=
            p.ctx.props.limits.maxComputeWorkGroupCount[0]);
  const gpu::GpuPush push{glm::uvec4(uint32_t(jobs.size()), output_texels, 0u, 0u)};
  if (Status s = p.ctx.dispatch(p.pipeline, push, output_texels, nullptr, p.ctx.descriptor_set); !s)
    return s;
  ++info.dispatches;
  const auto* result = static_cast<const DenoiseTexel*>(results->mapped);
  for (const FaceJob& job : jobs) {
    const int size = out[job.rdm].id.size;
    for (int t = 0; t < size * size; ++t) {
      const DenoiseTexel& read = texels[job.task.sources.x + uint32_t(t)];
      const bool filtered = shared::denoiseNeeded(read, settings.min_relative_error);
      storeDenoisedTexel(out[job.rdm], job.face, t % size, t / size, read,
                         result[job.task.info.w + uint32_t(t)], filtered, stats);
    }
  }
  info.texels += output_texels;
  texels.clear(), source_of.clear(), jobs.clear(), output_texels = 0;
  return {};
}

Expected<std::unique_ptr<VulkanDenoiser>> VulkanDenoiser::create(const std::string& device) {
  auto impl = std::make_unique<Impl>();
  if (Status s = impl->program.create(device, "rdm-denoise", spirv::kDenoiseComp,
                                      spirv::kDenoiseCompWords, 4);
      !s)
    return s;
  return std::unique_ptr<VulkanDenoiser>(new VulkanDenoiser(std::move(impl)));
}

Status VulkanDenoiser::denoise(const std::vector<DenoiseInput>& batch,
                               const DenoiseSettings& settings, std::vector<RdmData>& out,
                               DenoiseStats& stats) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  RDM_CHECK(settings.radius < 256);
  out.resize(batch.size());
  for (size_t k = 0; k < batch.size(); ++k) {
    const RdmData& center = *batch[k].center;
    out[k] = center;
    ++stats.rdms;
    if (!hasStandardError(center)) continue;  // no guide: kept, as denoiseRdm keeps it
    const uint32_t size = uint32_t(center.id.size),
                   window = uint32_t(denoiseWindow(center, settings));
    for (int f = 0; f < 6; ++f) {
      if (center.skipped[size_t(f)]) continue;
      if (m.output_texels + size * size > kBandTexels) {
        if (Status s = m.flush(settings, out, stats); !s) return s;
      }
      const std::vector<const RdmData*> set =
          denoiseFaceSet(center, f, batch[k].neighbours[size_t(f / 2)], settings);
      GpuDenoiseTask task{glm::uvec4(0u), glm::uvec4(0u)};
      for (size_t q = 0; q < set.size(); ++q) {
        const uint32_t first = m.source(*set[q], f);
        if (q < 4)
          task.sources[int(q)] = first;
        else
          task.info.x = first;
      }
      task.info.y = uint32_t(set.size());
      task.info.z = size | window << 12 | uint32_t(settings.radius) << 20;
      task.info.w = m.output_texels;
      m.jobs.push_back({k, f, task});
      m.output_texels += size * size;
    }
  }
  if (Status s = m.flush(settings, out, stats); !s) return s;
  m.info.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {};
}

#endif  // RDM_HAVE_VULKAN

VulkanDenoiser::VulkanDenoiser(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanDenoiser::~VulkanDenoiser() = default;

const VulkanDeviceInfo& VulkanDenoiser::device() const {
  return impl_->device;
}
const VulkanDenoiseInfo& VulkanDenoiser::info() const {
  return impl_->info;
}

}  // namespace rdm
