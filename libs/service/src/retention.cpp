#include "rdm/service/retention.h"

#include <algorithm>

namespace rdm {

std::vector<std::string> chooseExpired(std::vector<RetentionCandidate> finished,
                                       uint64_t data_bytes, const RetentionPolicy& policy,
                                       double now) {
  std::sort(finished.begin(), finished.end(),
            [](const RetentionCandidate& a, const RetentionCandidate& b) { return a.seq < b.seq; });
  long long kept = (long long)finished.size();
  uint64_t bytes = data_bytes;
  auto over = [&] {
    return (policy.keep_jobs > 0 && kept > policy.keep_jobs) ||
           (policy.max_data_bytes > 0 && bytes > policy.max_data_bytes);
  };
  std::vector<std::string> out;
  for (const RetentionCandidate& c : finished) {
    if (!over()) break;
    if (c.pinned) continue;
    if (c.last_fetch > 0.0 && now - c.last_fetch < policy.fetch_grace_s) continue;
    out.push_back(c.id);
    --kept;
    bytes -= std::min(bytes, c.bytes);
  }
  return out;
}

}  // namespace rdm
