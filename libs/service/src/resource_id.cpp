#include "rdm/service/resource_id.h"

#include <mutex>
#include <random>

namespace rdm {

std::string newId(char kind) {
  static std::mutex mutex;
  static std::mt19937_64 rng{std::random_device{}()};
  std::lock_guard<std::mutex> lock(mutex);
  uint64_t v = rng();
  static const char kHex[] = "0123456789abcdef";
  std::string id(1, kind);
  for (int i = 15; i >= 0; --i) id.push_back(kHex[(v >> (4 * i)) & 15]);
  return id;
}

bool validId(const std::string& id, char kind) {
  if (id.size() != 17 || id[0] != kind) return false;
  for (size_t i = 1; i < id.size(); ++i) {
    char c = id[i];
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace rdm
