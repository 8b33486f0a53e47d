#include "rdm/base/hash.h"

#include <xxhash.h>

#include <cstdio>

namespace rdm {

uint64_t contentHash(std::string_view bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
}

std::string contentHashHex(std::string_view bytes) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(contentHash(bytes)));
  return buf;
}

}  // namespace rdm
