// The device passes of a Vulkan job's results (job_finisher.h): the BC6H encoder and the
// denoiser on the daemon's Vulkan device, each created once, used by one job at a time.
#include "job_finisher.h"
#include "rdm/base/log.h"

namespace rdm {

namespace {

// A device's denoise() under the finisher's device lock, so that jobs finishing at once on
// their own threads take turns.
class LockedDenoiser final : public DenoiseDevice {
 public:
  LockedDenoiser(std::shared_ptr<VulkanDenoiser> device, std::shared_ptr<std::mutex> mutex)
      : device_(std::move(device)), mutex_(std::move(mutex)) {}
  Status denoise(const std::vector<DenoiseInput>& batch, const DenoiseSettings& settings,
                 std::vector<RdmData>& out, DenoiseStats& stats) override {
    std::lock_guard lock(*mutex_);
    return device_->denoise(batch, settings, out, stats);
  }
  size_t batchRdms() const override { return device_->batchRdms(); }

 private:
  std::shared_ptr<VulkanDenoiser> device_;
  std::shared_ptr<std::mutex> mutex_;
};

// `made`'s program, or null after logging why the device could not make it.
template <class T>
std::shared_ptr<T> madeOrLogged(Expected<std::unique_ptr<T>> made, const char* what) {
  if (made) return std::shared_ptr<T>(std::move(*made));
  logEvent(LogLevel::kWarn, "device_pass",
           {{"pass", what}, {"message", made.error() + "; the CPU does it instead"}});
  return nullptr;
}

}  // namespace

Bc6hEncodeFn JobFinisher::bc6hEncoderFor(const JobRecord& record) {
  if (device_.empty() || record.backend != "vulkan" || record.radiance != RadianceFormat::kBc6h)
    return {};
  std::shared_ptr<VulkanBc6hEncoder> encoder;
  {
    std::lock_guard lock(*device_mutex_);
    if (!bc6h_) bc6h_ = madeOrLogged(VulkanBc6hEncoder::create(device_), "bc6h");
    encoder = bc6h_;
  }
  if (!encoder) return {};
  return [encoder, mutex = device_mutex_](const Image& image) {
    std::lock_guard lock(*mutex);
    return encoder->encode(image);
  };
}

std::unique_ptr<DenoiseDevice> JobFinisher::denoiserFor(const JobRecord& record) {
  if (device_.empty() || record.backend != "vulkan" || !record.denoise) return nullptr;
  std::shared_ptr<VulkanDenoiser> denoiser;
  {
    std::lock_guard lock(*device_mutex_);
    if (!denoiser_) denoiser_ = madeOrLogged(VulkanDenoiser::create(device_), "denoise");
    denoiser = denoiser_;
  }
  if (!denoiser) return nullptr;
  return std::make_unique<LockedDenoiser>(denoiser, device_mutex_);
}

}  // namespace rdm
