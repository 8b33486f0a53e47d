// A prepared job inside the executor: its world, the RDMs it bakes, their work units and
// how far they got. Fields below `mutex-guarded` are touched only under JobManager's mutex;
// texels of distinct units are written by workers without it (disjoint rects).
//
// A progressive job (docs/api.md, "Progressive incremental jobs") first bakes its plan at
// the preview settings into a second session (no checkpoints, no slot sets), publishes it,
// then bakes the final pass, whose units are checkpointed and resumable.
#pragma once

#include <atomic>
#include <exception>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/bake/rebake_selection.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/status.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "rdm/service/job.h"

namespace rdm {

// Unit indices of the preview pass carry this bit; final-pass units do not.
constexpr size_t kPreviewUnit = size_t(1) << (sizeof(size_t) * 8 - 1);

struct PreviewPass {
  BakeSettings settings;
  std::unique_ptr<BakeSession> session;
  std::vector<BakeUnit> units;
  // mutex-guarded
  size_t cursor = 0;  // units handed out
  size_t left = 0;    // units not yet finished
};

struct ActiveJob {
  std::string id;
  BakeMode mode = BakeMode::kFull;
  long long seq = 0;
  BakeSettings settings;
  std::shared_ptr<const Scene> scene;
  std::unique_ptr<VoxelWorld> world;
  std::vector<RdmId> all;   // every RDM of the target version, canonical
  std::vector<RdmId> plan;  // RDMs this job bakes, in visibility order
  AtlasView view;           // layout of the result, origin of every RDM
  // Allocates an RDM's texels at its first unit and hands them to `spill` when its last
  // unit is booked, so a job holds the texels of the RDMs in flight only; its units()
  // schedule.
  std::unique_ptr<BakeSession> storage;
  std::shared_ptr<RdmSpill> spill;  // the plan's finished RDMs, final pass
  std::vector<BakeUnit> units;
  std::vector<int> local_index;  // unit's index among its RDM's units
  std::optional<PreviewPass> preview;
  bool vulkan = false;  // the Vulkan worker bakes it (JobRecord::backend)
  // Mirrors `cancelled` for a Vulkan bake in progress, which checks it between dispatches.
  std::atomic<bool> cancel_flag{false};
  // Set while the job is prepared or finished when it is cancelled or the daemon stops: the
  // preparation returns between its steps, the face light between faces (kCancelled).
  std::atomic<bool> abort{false};
  // Set by JobFinisher::finalize on the finishing thread: the baked RDMs' relative errors.
  BakeReport noise;
  double denoise_seconds = 0.0;  // likewise: the denoiser's wall time (0: not asked for)

  // mutex-guarded
  std::vector<uint8_t> unit_state;  // 0 pending, 1 running, 2 done
  size_t cursor = 0;                // no pending unit before it
  std::vector<int> units_left;      // per plan RDM
  std::vector<RdmRecord> records;   // per plan RDM: accumulated slot sets
  int in_flight = 0;
  bool cancelled = false;
  Status failure;  // a unit could not be checkpointed for lack of space: the job fails

  bool previewPending() const { return preview && preview->cursor < preview->units.size(); }
  bool previewDone() const { return !preview || preview->left == 0; }
  bool hasPending() const { return !cancelled && (previewPending() || cursor < units.size()); }
  bool finishable() const {
    return in_flight == 0 && (cancelled || (cursor >= units.size() && previewDone()));
  }
  int passes() const { return preview ? 2 : 1; }
  // After the last unit of plan RDM r is booked: its texels go to the spill.
  void releaseFinished(size_t r) {
    storage->releaseRdm(r, [&](const RdmData& d) { spill->append(d); });
  }
};

// Workers take units of the job that sorts first: incremental before full, then fewer
// units, then older.
inline auto jobPriority(const ActiveJob& j) {
  return std::make_tuple(j.mode == BakeMode::kFull, j.units.size(), j.seq);
}

// The failure of a job whose work threw while `doing` ("preparing the job"): kTooLarge with
// what to change for std::bad_alloc (the job's error says it), kInternal otherwise (the job's
// error points at the server log, where the exception's text goes).
Status jobFailure(const std::exception& e, const std::string& doing);

// The texels of a preview `session`'s RDMs keyed for a PublishedPass, at the pass's own
// sizes (a preview's RDMs are smaller than the job's; delta.bin sends them so,
// rdm/preview_pass.h).
std::map<RdmKey, Image> snapshotImages(BakeSession& session);

}  // namespace rdm
