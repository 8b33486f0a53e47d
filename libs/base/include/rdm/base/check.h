// Programmer-bug channel: RDM_CHECK aborts with a message. Bad input, IO and device
// failures never use it; they travel as rdm::Status / rdm::Expected (status.h).
#pragma once

#include <cstdio>
#include <cstdlib>

#define RDM_CHECK(cond)                                                                 \
  do {                                                                                  \
    if (!(cond)) {                                                                      \
      std::fprintf(stderr, "%s:%d: RDM_CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                     \
    }                                                                                   \
  } while (0)
