#include "local_bake.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

namespace rdm::cli {

std::vector<RdmId> shardRdms(const VoxelWorld& world, const BakeSettings& settings, int shard_index,
                             int shard_count) {
  std::vector<RdmId> all = listRdms(world, settings), mine;
  const size_t count = size_t(std::max(1, shard_count));
  for (size_t i = 0; i < all.size(); ++i) {
    if (int(i % count) == shard_index) mine.push_back(all[i]);
  }
  return mine;
}

BakeResult runLocalBake(const VoxelWorld& world, const BakeSettings& settings,
                        const std::vector<RdmId>& rdms, const BakeOptions& options,
                        const std::function<void(const LocalBakeProgress&)>& on_progress) {
  const auto start = std::chrono::steady_clock::now();
  BakeSession session(world, settings, rdms, options);
  const std::vector<BakeUnit>& units = session.units();
  std::vector<std::atomic<int>> remaining(session.rdms().size());
  uint64_t texels_total = 0;
  for (const BakeUnit& u : units) {
    remaining[size_t(u.rdm)].fetch_add(1);
    texels_total += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  }
  std::atomic<int> rdms_done{0};
  for (auto& r : remaining) rdms_done += r.load() == 0 ? 1 : 0;
  std::atomic<size_t> next{0};
  std::atomic<uint64_t> rays{0}, texels_done{0};
  std::atomic<int> workers_left{0};
  std::atomic<bool> cancelled{false};
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < units.size();) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      rays += session.runUnit(i);
      const BakeUnit& u = units[i];
      texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
      if (remaining[size_t(u.rdm)].fetch_sub(1) == 1) ++rdms_done;
    }
    --workers_left;
  };
  const int thread_count = options.threads > 0
                               ? options.threads
                               : int(std::max(1u, std::thread::hardware_concurrency()));
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto report = [&] {
    if (on_progress) {
      on_progress({texels_done.load(), texels_total, rdms_done.load(), int(remaining.size()),
                   rays.load(), elapsed()});
    }
  };
  report();  // the 0 % line, before any work
  workers_left = thread_count;
  std::vector<std::thread> threads;
  for (int t = 0; t < thread_count; ++t) threads.emplace_back(work);
  while (workers_left.load() > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    report();
  }
  for (std::thread& t : threads) t.join();
  if (!cancelled) report();
  return session.finish(elapsed(), rays.load(), cancelled.load());
}

}  // namespace rdm::cli
