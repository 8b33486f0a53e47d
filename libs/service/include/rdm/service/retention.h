// Retention of finished jobs (rdm serve --keep-jobs, --max-data-bytes, --fetch-grace;
// docs/api.md, "Deleting and retention"), so a daemon runs for months on a fixed disk. The
// choice alone: no files, no threads, no clock (JobManager gathers the candidates, asks
// chooseExpired and deletes what it names).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rdm {

struct RetentionPolicy {
  long long keep_jobs = 1000;   // finished (succeeded, failed, cancelled) jobs kept; 0: no limit
  uint64_t max_data_bytes = 0;  // bytes the data directory may hold; 0: no limit
  double fetch_grace_s = 300;   // a job whose results were fetched this recently is kept
};

// A finished job as retention sees it.
struct RetentionCandidate {
  std::string id;
  long long seq = 0;        // admission order: lower is older
  uint64_t bytes = 0;       // its directory's size on disk
  bool pinned = false;      // an unfinished job or a kept result needs it, or it is its
                            // scene's newest job that can be a base (never expires)
  double last_fetch = 0.0;  // unix seconds of the last fetch of its results; 0: never
};

// The jobs to expire, oldest (lowest seq) first: while more than keep_jobs finished jobs
// remain, or `data_bytes` (the data directory's size) is above max_data_bytes, the oldest
// job that is neither pinned nor fetched within fetch_grace_s of `now` goes, and its bytes
// count as freed. What cannot go stays: the limits are targets, never a reason to delete a
// job in use.
std::vector<std::string> chooseExpired(std::vector<RetentionCandidate> finished,
                                       uint64_t data_bytes, const RetentionPolicy& policy,
                                       double now);

}  // namespace rdm
