// The one device-selection policy of `rdm bake --device` and `rdm-viewer --device`
// (rdm/vulkan_device.h), on made-up device lists, and the bootstrap the bake and the viewer
// share (rdm/vulkan/vulkan_bootstrap.h), whose submit-and-wait runs on the machine's device.
#include <gtest/gtest.h>

#if RDM_HAVE_VULKAN
#include "rdm/vulkan/vulkan_bootstrap.h"
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

TEST(VulkanBootstrap, MemoryTypeLookupRefusesAnImpossibleRequestByName) {
  constexpr VkMemoryPropertyFlags kHost =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkPhysicalDeviceMemoryProperties memory{};
  memory.memoryTypeCount = 2;
  memory.memoryTypes[0].propertyFlags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  memory.memoryTypes[1].propertyFlags = kHost;
  EXPECT_EQ(findMemoryType(memory, 0x3, 0).value(), 0u);
  EXPECT_EQ(findMemoryType(memory, 0x3, kHost).value(), 1u);
  auto excluded = findMemoryType(memory, 0x1, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  ASSERT_FALSE(excluded.ok());
  EXPECT_EQ(excluded.status().code(), StatusCode::kDevice);
  EXPECT_NE(excluded.error().find("no memory type with HOST_VISIBLE among the allowed types 0x1"),
            std::string::npos)
      << excluded.error();
  auto none = findMemoryType(memory, 0x3, kHost | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().find("DEVICE_LOCAL|HOST_VISIBLE|HOST_COHERENT"), std::string::npos)
      << none.error();
}

TEST(VulkanBootstrap, SubmitAndWaitRunsOneShotCommandBuffersOnTheComputeQueue) {
  auto instance = VulkanInstance::create({});
  ASSERT_TRUE(instance.ok()) << instance.error();
  auto choice = chooseVulkanDevice(instance->handle(), "", QueueNeed::kCompute);
  ASSERT_TRUE(choice.ok()) << choice.error();
  EXPECT_TRUE(choice->info.has_compute);
  auto device = VulkanDevice::create(choice->physical, choice->queue_family, {});
  ASSERT_TRUE(device.ok()) << device.error();
  int recorded = 0;
  for (int i = 0; i < 2; ++i) {
    const Status s = device->submitAndWait([&](VkCommandBuffer cmd) {
      EXPECT_NE(cmd, VK_NULL_HANDLE);
      ++recorded;
    });
    EXPECT_TRUE(s.ok()) << s.message();
  }
  EXPECT_EQ(recorded, 2);
  auto impossible = device->memoryType(0u, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  ASSERT_FALSE(impossible.ok());
  EXPECT_NE(impossible.error().find("HOST_VISIBLE"), std::string::npos);
}

TEST(VulkanBootstrap, AQueueFamilyFilterThatRefusesAllLeavesNoDevice) {
  auto instance = VulkanInstance::create({});
  ASSERT_TRUE(instance.ok()) << instance.error();
  auto none = chooseVulkanDevice(instance->handle(), "", QueueNeed::kGraphics,
                                 [](VkPhysicalDevice, uint32_t) { return false; });
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), StatusCode::kDevice);
  EXPECT_NE(none.error().find("no device with a graphics queue"), std::string::npos)
      << none.error();
}

}  // namespace
}  // namespace rdm
#else
TEST(VulkanDevice, NotBuilt) {
  GTEST_SKIP() << "built with -DRDM_VULKAN=OFF: no Vulkan layer";
}
#endif
