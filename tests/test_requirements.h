// What a test needs from the machine (a Vulkan device, xvfb-run). The README's test command
// installs all of it and CI always has lavapipe, so a missing requirement fails the test;
// RDM_TEST_ALLOW_SKIP=1 turns that into a skip naming what is missing, for a developer's
// machine without a Vulkan driver.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

namespace rdm::test {

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
