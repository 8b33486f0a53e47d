// What a test needs from the machine (a Vulkan device, xvfb-run). The README's test command
// installs all of it and CI always has lavapipe, so a missing requirement fails the test;
// RDM_TEST_ALLOW_SKIP=1 turns that into a skip naming what is missing, for a developer's
// machine without a Vulkan driver.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

namespace rdm::test {

// g++ defines __SANITIZE_*__; clang (the ASan/UBSan pass of scripts/test.sh) answers
// __has_feature instead.
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define RDM_TEST_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || defined(RDM_TEST_SANITIZED)
constexpr bool kSanitized = true;  // shadow memory and instrumentation change RSS, CPU
                                   // time and the descriptors a process opens
#else
constexpr bool kSanitized = false;
#endif

inline bool skipsAllowed() {
  const char* v = std::getenv("RDM_TEST_ALLOW_SKIP");
  return v && std::strcmp(v, "1") == 0;
}

}  // namespace rdm::test

// Ends the calling test when `available` is false: a skip with RDM_TEST_ALLOW_SKIP=1, else a
// failure. `what` streams into the message.
#define RDM_TEST_REQUIRE(available, what)                                                     \
  do {                                                                                        \
    if (!(available)) {                                                                       \
      if (::rdm::test::skipsAllowed()) GTEST_SKIP() << what << " (RDM_TEST_ALLOW_SKIP=1)";    \
      FAIL() << what << ": scripts/install_deps.sh installs it; RDM_TEST_ALLOW_SKIP=1 skips"; \
    }                                                                                         \
  } while (0)
