// The one device-selection policy of `rdm bake --device` and `rdm-viewer --device`
// (rdm/vulkan_device.h), on made-up device lists: no device is needed.
#include <gtest/gtest.h>

#if RDM_HAVE_VULKAN
#include "rdm/vulkan/vulkan_device.h"

namespace rdm {
namespace {

std::vector<VulkanDeviceInfo> devices() {
  VulkanDeviceInfo cpu{0, "llvmpipe (LLVM 15.0.6, 256 bits)", "cpu", "", 0, true, true};
  VulkanDeviceInfo compute_only{1, "Compute Card", "discrete-gpu", "", 0, true, false};
  VulkanDeviceInfo igpu{2, "Intel(R) UHD Graphics", "integrated-gpu", "", 0, true, true};
  return {cpu, compute_only, igpu};
}

TEST(VulkanDevice, EmptyPicksTheBestTypeWithTheQueue) {
  EXPECT_EQ(selectVulkanDevice(devices(), "", QueueNeed::kCompute).value(), 1);
  EXPECT_EQ(selectVulkanDevice(devices(), "", QueueNeed::kGraphics).value(), 2);
  std::vector<VulkanDeviceInfo> only_cpu = {devices()[0]};
  EXPECT_EQ(selectVulkanDevice(only_cpu, "", QueueNeed::kGraphics).value(), 0);
  auto none = selectVulkanDevice({}, "", QueueNeed::kCompute);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), StatusCode::kDevice);
}

TEST(VulkanDevice, ByIndexOrNameAndRefusalsNameTheDevices) {
  EXPECT_EQ(selectVulkanDevice(devices(), "0", QueueNeed::kGraphics).value(), 0);
  EXPECT_EQ(selectVulkanDevice(devices(), "uhd", QueueNeed::kCompute).value(), 2);
  auto out_of_range = selectVulkanDevice(devices(), "3", QueueNeed::kCompute);
  ASSERT_FALSE(out_of_range.ok());
  EXPECT_EQ(out_of_range.status().field(), "device");
  EXPECT_NE(out_of_range.error().find("devices: 0 'llvmpipe"), std::string::npos)
      << out_of_range.error();
  auto unknown = selectVulkanDevice(devices(), "nvidia", QueueNeed::kCompute);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("no device named 'nvidia'"), std::string::npos);
  auto no_graphics = selectVulkanDevice(devices(), "compute card", QueueNeed::kGraphics);
  ASSERT_FALSE(no_graphics.ok());
  EXPECT_NE(no_graphics.error().find("has no graphics queue"), std::string::npos);
}

TEST(VulkanDevice, ResultsMapToDeviceErrorsNamingTheCall) {
  EXPECT_TRUE(vkStatus("vkCreateDevice", VK_SUCCESS).ok());
  const Status lost = vkStatus("vkQueueSubmit", VK_ERROR_DEVICE_LOST);
  EXPECT_EQ(lost.code(), StatusCode::kDevice);
  EXPECT_NE(lost.message().find("vkQueueSubmit failed: VK_ERROR_DEVICE_LOST"), std::string::npos);
}

}  // namespace
}  // namespace rdm
#else
TEST(VulkanDevice, NotBuilt) {
  GTEST_SKIP() << "built with -DRDM_VULKAN=OFF: no Vulkan layer";
}
#endif
