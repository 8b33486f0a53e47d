#include "rdm/service/job_records.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "rdm/base/build_id.h"
#include "rdm/base/check.h"
#include "rdm/base/clock.h"
#include "rdm/base/log.h"
#include "rdm/scene/bake_settings_json.h"
#include "rdm/service/resource_id.h"

namespace rdm {
namespace {

// "settings.spp 64 here, 8 asked; backend ..." : why `base` cannot be an exact job's base.
std::string baseMismatch(const JobRecord& base, const JobRecord& job) {
  std::vector<std::string> parts;
  auto differ = [&](const std::string& what, const std::string& had, const std::string& asked) {
    if (had != asked) parts.push_back(what + " " + had + " there, " + asked + " asked");
  };
  const nlohmann::json had = bakeSettingsToJson(base.settings);
  const nlohmann::json asked = bakeSettingsToJson(job.settings);
  for (const auto& [key, value] : asked.items())
    differ("settings." + key, had.value(key, nlohmann::json()).dump(), value.dump());
  differ("build", base.build, job.build);
  differ("backend", base.backend, job.backend);
  differ("device", base.device, job.device);
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : "; ") + p;
  return out;
}

}  // namespace

void JobRecords::restore(std::vector<JobRecord> loaded) {
  std::sort(loaded.begin(), loaded.end(),
            [](const JobRecord& a, const JobRecord& b) { return a.seq < b.seq; });
  for (JobRecord& job : loaded) {
    next_seq_ = std::max(next_seq_, job.seq + 1);
    if (!terminal(job.state)) {
      if (job.cancel_requested) {
        job.state = JobState::kCancelled, job.finished = nowSeconds();
        store_.removeUnits(job.id);
        // The record on disk keeps cancel_requested, so a failed save cancels it again at
        // the next start.
        if (Status s = store_.saveJob(job); !s)
          logEvent(LogLevel::kWarn, "job",
                   {{"message", "job " + std::string(job.id) + ": " + s.message()}});
      } else if (!quarantine(job)) {
        job.state = JobState::kQueued;  // resumes; finished units are restored on prepare
        to_prepare_.push_back(job.id);
      }
    }
    add(std::move(job));
  }
}

bool JobRecords::quarantine(JobRecord& job) {
  if (job.runs_started < 2) return false;
  const bool baking = store_.loadPlan(job.id).has_value();
  const std::string times =
      job.runs_started == 2 ? "twice" : std::to_string(job.runs_started) + " times";
  job.state = JobState::kFailed, job.finished = nowSeconds();
  job.error = "the daemon stopped " + times + " while this job was being " +
              (baking ? "baked" : "prepared") +
              "; quarantined, not resumed: it may need more memory than this server has (see "
              "the server log); submit it again with a smaller settings.max_hemisphere, "
              "\"radiance\": \"half\" or the scene in smaller parts";
  logEvent(LogLevel::kError, "job",
           {{"id", job.id}, {"state", "failed"}, {"scene", job.scene_id}, {"reason", job.error}});
  store_.removeUnits(job.id);
  store_.removeOutputs(job.id);
  if (Status s = store_.saveJob(job); !s)
    logEvent(LogLevel::kWarn, "job",
             {{"message", "job " + std::string(job.id) + ": " + s.message()}});
  return true;
}

Expected<JobRecord> JobRecords::draft(const SubmitRequest& req) const {
  auto info = scenes_.info(req.scene_id);
  if (!info) return Status::notFound("no scene '" + req.scene_id + "'");
  JobRecord job;
  job.scene_id = req.scene_id;
  job.scene_version = req.version ? req.version : info->version;
  if (job.scene_version < 1 || job.scene_version > info->version) {
    return Status::invalidField("version",
                                "the scene has versions 1.." + std::to_string(info->version));
  }
  job.settings = req.settings;
  job.mode = req.mode;
  job.radiance = req.radiance;
  job.face_light_spp = req.face_light_spp;
  job.denoise = req.denoise;
  job.memory_estimate = req.memory_estimate;
  job.build = buildId();
  job.created = nowSeconds();
  return job;
}

Status JobRecords::chooseBase(const SubmitRequest& req, JobRecord& job) const {
  auto compatible = [&](const JobRecord& b, bool strict) {
    return b.scene_id == job.scene_id && b.state == JobState::kSucceeded &&
           b.mode != BakeMode::kFast &&
           (!strict || (b.settings == job.settings && b.build == job.build &&
                        b.backend == job.backend && b.device == job.device));
  };
  const bool strict = job.mode == BakeMode::kExact;
  if (!req.base_job.empty()) {
    auto it = jobs_.find(req.base_job);
    if (it == jobs_.end()) return Status::notFound("no job '" + req.base_job + "'", "base_job");
    const JobRecord& b = it->second;
    if (b.scene_id != job.scene_id)
      return Status::conflict("base_job belongs to another scene", "base_job");
    if (b.state != JobState::kSucceeded)
      return Status::conflict("base_job has not succeeded", "base_job");
    if (!scenes_.get(b.scene_id, b.scene_version)) {
      return Status::conflict("base_job's scene version " + std::to_string(b.scene_version) +
                                  " is no longer kept (docs/spec.md section 8.3); use a newer base",
                              "base_job");
    }
    if (strict && !compatible(b, true)) {
      const std::string why =
          b.mode == BakeMode::kFast ? "it is a fast bake" : baseMismatch(b, job);
      return Status::conflict(
          "mode exact needs a full or exact base job with the same settings, build, backend and "
          "device; job " +
              b.id + " differs: " + why,
          "base_job");
    }
    job.base_job = b.id;
    return {};
  }
  const JobRecord* best = nullptr;
  const auto found = scene_jobs_.find(job.scene_id);
  static const std::vector<const JobRecord*> kNoJobs;
  const auto& candidates = found == scene_jobs_.end() ? kNoJobs : found->second;
  for (bool s : {true, strict}) {  // prefer same settings; fast may fall back to any
    for (auto b = candidates.rbegin(); b != candidates.rend() && !best; ++b) {
      // Newest first, and only one whose scene version is still kept: a PATCH's prune or a
      // version DELETE may have dropped it since the job succeeded, and the new job diffs
      // against it when it starts.
      if (compatible(**b, s) && scenes_.get((*b)->scene_id, (*b)->scene_version)) best = *b;
    }
    if (best) break;
  }
  if (!best) return noBase(job, candidates);
  job.base_job = best->id;
  return {};
}

Status JobRecords::noBase(const JobRecord& job,
                          const std::vector<const JobRecord*>& candidates) const {
  const std::string head = "no compatible base job for mode " + std::string(modeName(job.mode));
  for (auto b = candidates.rbegin(); b != candidates.rend(); ++b) {
    const JobRecord& near = **b;  // the newest full or exact bake: say what keeps it out
    if (near.state != JobState::kSucceeded || near.mode == BakeMode::kFast) continue;
    if (!scenes_.get(near.scene_id, near.scene_version)) {
      return Status::conflict(head + ": job " + near.id + "'s scene version " +
                                  std::to_string(near.scene_version) +
                                  " is no longer kept; run a full bake",
                              "base_job");
    }
    return Status::conflict(head + ": job " + near.id + " differs (" + baseMismatch(near, job) +
                                "); run a full bake with these settings, or submit with the "
                                "base job's settings",
                            "base_job");
  }
  return Status::conflict(head + ": the scene has no full bake yet; run a full bake first",
                          "base_job");
}

Expected<JobRecord> JobRecords::admit(const SubmitRequest& req, JobRecord job, int max_jobs) {
  const int active = int(unfinished_.size());
  if (active >= max_jobs) {
    return Status::error(StatusCode::kBusy, "the server holds " + std::to_string(active) +
                                                " unfinished jobs (limit " +
                                                std::to_string(max_jobs) + "); retry later");
  }
  // The scene or version may have been deleted since draft() (JobManager deletes them under
  // the lock admit() runs under): 404 as GET /v1/scenes/{id}?version= answers.
  if (!scenes_.info(job.scene_id)) return Status::notFound("no scene '" + job.scene_id + "'");
  if (auto kept = scenes_.find(job.scene_id, job.scene_version); !kept) return kept.status();
  if (job.mode != BakeMode::kFull) {
    if (Status s = chooseBase(req, job); !s) return s;
  }
  job.id = newId('j');
  job.seq = next_seq_++;
  if (Status s = store_.saveJob(job); !s) {
    std::error_code ec;
    std::filesystem::remove_all(store_.jobDir(job.id), ec);  // no empty job directory is left
    return s;
  }
  add(job);
  to_prepare_.push_back(job.id);
  logEvent(LogLevel::kInfo, "job",
           {{"id", job.id},
            {"state", "queued"},
            {"scene", job.scene_id},
            {"version", job.scene_version},
            {"mode", modeName(job.mode)},
            {"base_job", job.base_job}});
  return job;
}

Expected<JobRecord> JobRecords::cancel(const std::string& id, bool finishing) {
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return Status::notFound("no job '" + id + "'");
  JobRecord& job = it->second;
  if (terminal(job.state))
    return Status::conflict("job already " + std::string(stateName(job.state)));
  if (finishing && !job.cancel_requested) {
    return Status::conflict("job " + id +
                            " is writing its results and will succeed; it can no longer " +
                            "be cancelled");
  }
  // The cancel is on disk before it is acknowledged or acted on: a failed save changes
  // nothing, so no restart can resume a job whose cancel was answered.
  JobRecord cancelled = job;
  cancelled.cancel_requested = true;
  auto queued = std::find(to_prepare_.begin(), to_prepare_.end(), id);
  const bool never_prepared = queued != to_prepare_.end();
  if (never_prepared) cancelled.state = JobState::kCancelled, cancelled.finished = nowSeconds();
  if (Status s = store_.saveJob(cancelled); !s) return s;
  job = cancelled;
  if (never_prepared) {  // cancelled at once
    to_prepare_.erase(queued);
    end(job, JobState::kCancelled);
  }
  return job;
}

const JobRecord* JobRecords::find(const std::string& id) const {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : &it->second;
}

JobRecord& JobRecords::at(const std::string& id) {
  auto it = jobs_.find(id);
  RDM_CHECK(it != jobs_.end());
  return it->second;
}

std::vector<JobRecord> JobRecords::list() const {
  std::vector<JobRecord> out;
  for (const auto& [id, j] : jobs_) out.push_back(j);
  std::sort(out.begin(), out.end(),
            [](const JobRecord& a, const JobRecord& b) { return a.seq > b.seq; });
  return out;
}

std::set<long long> JobRecords::versionsInUse(const std::string& scene_id) const {
  std::set<long long> out;
  for (const std::string& id : unfinished_) {
    const JobRecord& j = jobs_.at(id);
    if (j.scene_id != scene_id) continue;
    out.insert(j.scene_version);
    auto base = jobs_.find(j.base_job);  // the base's scene is diffed when the job starts
    if (base != jobs_.end()) out.insert(base->second.scene_version);
  }
  const auto found = scene_jobs_.find(scene_id);
  if (found == scene_jobs_.end()) return out;
  for (auto j = found->second.rbegin(); j != found->second.rend(); ++j) {
    if ((*j)->state == JobState::kSucceeded && (*j)->mode != BakeMode::kFast) {
      out.insert((*j)->scene_version);  // the newest that can be a base
      break;
    }
  }
  return out;
}

void JobRecords::countStates(JobGauges& g) const {
  for (JobState s : {JobState::kQueued, JobState::kRunning, JobState::kSucceeded, JobState::kFailed,
                     JobState::kCancelled}) {
    g.jobs_by_state[stateName(s)] = 0;
  }
  for (const auto& [id, j] : jobs_) {
    ++g.jobs_by_state[stateName(j.state)];
    g.queue_depth += terminal(j.state) ? 0 : 1;
  }
}

std::optional<size_t> JobRecords::nextToPrepare(uint64_t held, bool none_running, uint64_t budget) {
  // Incremental jobs are prepared first so they overtake queued full bakes.
  std::stable_partition(to_prepare_.begin(), to_prepare_.end(),
                        [&](const std::string& id) { return at(id).mode != BakeMode::kFull; });
  for (size_t i = 0; i < to_prepare_.size(); ++i) {
    const uint64_t need = at(to_prepare_[i]).memory_estimate;
    if (none_running || budget == 0 || held + need <= budget) return i;
  }
  return std::nullopt;
}

std::string JobRecords::takeQueued(size_t index) {
  RDM_CHECK(index < to_prepare_.size());
  std::string id = to_prepare_[index];
  to_prepare_.erase(to_prepare_.begin() + long(index));
  return id;
}

void JobRecords::countRun(const std::string& id) {
  at(id).runs_started++;
  runs_here_.insert(id);
  save(id);
}

void JobRecords::giveBackRuns() {
  for (const std::string& id : runs_here_) {
    JobRecord& job = at(id);
    if (terminal(job.state)) continue;
    job.runs_started = std::max(0, job.runs_started - 1);
    save(id);
  }
  runs_here_.clear();
}

void JobRecords::end(JobRecord& job, JobState state) {
  RDM_CHECK(terminal(state));
  job.state = state, job.finished = nowSeconds();
  unfinished_.erase(job.id);
  metrics_.jobFinished(stateName(state));
  ++ended_;
}

void JobRecords::fail(const std::string& id, const std::string& message, StatusCode code) {
  JobRecord& job = at(id);
  if (code == StatusCode::kNoSpace) {
    job.error =
        "the server's data directory is full, so a result could not be written; free space "
        "and submit the job again";
  } else if (code == StatusCode::kConflict || code == StatusCode::kTooLarge) {
    // What the job needs and this server lacks (a device, memory): the client's to act on.
    job.error = message;
  } else if (code == StatusCode::kCorrupt) {
    // Stored data the job read failed its checksum: named by file, slot and level, without
    // the server's directories ("<dir>/rdms.store: the texels of slot ... fail ...").
    const size_t colon = message.find(": ");
    const size_t slash = message.rfind('/', colon);
    job.error =
        "damaged stored data, not built upon: " +
        (slash == std::string::npos || colon == std::string::npos ? message
                                                                  : message.substr(slash + 1));
  } else {
    job.error = "the bake failed on the server; see the server log";
  }
  end(job, JobState::kFailed);
  save(id);
}

void JobRecords::save(const std::string& id) {
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return;
  if (Status s = store_.saveJob(it->second); !s)
    logEvent(LogLevel::kWarn, "job", {{"message", s.message()}});
}

JobRecord& JobRecords::add(JobRecord job) {
  const std::string id = job.id;
  JobRecord& added = jobs_[id] = std::move(job);
  scene_jobs_[added.scene_id].push_back(&added);  // callers add in seq order
  if (!terminal(added.state)) unfinished_.insert(id);
  return added;
}

const std::set<std::string>& JobRecords::originsOf(const std::string& id) {
  auto cached = origins_.find(id);
  if (cached != origins_.end()) return cached->second;
  static const std::set<std::string> kNone;
  const JobRecord* job = find(id);
  if (!job || job->state != JobState::kSucceeded) return kNone;  // no result yet: not cached
  std::set<std::string> origins;
  if (job->mode != BakeMode::kFull) {
    if (auto records = store_.loadRdmRecords(id)) {
      for (const RdmRecord& r : *records)
        if (r.origin_job != id) origins.insert(r.origin_job);
    } else if (!job->base_job.empty()) {
      // Unreadable: every RDM it copies came from its base or the base's origins.
      const std::string base = job->base_job;
      origins = originsOf(base);
      origins.insert(base);
    }
  }
  return origins_[id] = std::move(origins);
}

std::vector<std::string> JobRecords::dependents(const std::string& id) {
  std::vector<std::string> out;
  const JobRecord* job = find(id);
  if (!job || job->state != JobState::kSucceeded) return out;  // only results are copied
  // Bases and origins are jobs of the same scene.
  const auto found = scene_jobs_.find(job->scene_id);
  if (found == scene_jobs_.end()) return out;
  const std::vector<const JobRecord*> jobs = found->second;  // originsOf may not touch it
  for (auto j = jobs.rbegin(); j != jobs.rend(); ++j) {
    const JobRecord& other = **j;
    if (other.id == id) continue;
    bool needs = false;
    if (!terminal(other.state)) {
      needs = other.base_job == id || (!other.base_job.empty() && find(other.base_job) &&
                                       originsOf(other.base_job).count(id));
    } else if (other.state == JobState::kSucceeded) {
      needs = originsOf(other.id).count(id) > 0;
    }
    if (needs) out.push_back(other.id);
  }
  return out;
}

std::set<std::string> JobRecords::pinned() {
  std::set<std::string> out;
  std::vector<std::string> ids;
  for (const auto& [id, job] : jobs_) ids.push_back(id);
  for (const std::string& id : ids) {
    const JobRecord& job = jobs_.at(id);
    if (!terminal(job.state)) {
      if (!job.base_job.empty() && find(job.base_job)) {
        const std::string base = job.base_job;
        out.insert(base);
        const std::set<std::string>& origins = originsOf(base);
        out.insert(origins.begin(), origins.end());
      }
    } else if (job.state == JobState::kSucceeded) {
      const std::set<std::string>& origins = originsOf(id);
      out.insert(origins.begin(), origins.end());
    }
  }
  for (const auto& [scene, jobs] : scene_jobs_) {
    for (auto j = jobs.rbegin(); j != jobs.rend(); ++j) {
      if ((*j)->state == JobState::kSucceeded && (*j)->mode != BakeMode::kFast) {
        out.insert((*j)->id);  // the newest that can be a base
        break;
      }
    }
  }
  return out;
}

void JobRecords::erase(const std::string& id) {
  auto it = jobs_.find(id);
  RDM_CHECK(it != jobs_.end() && terminal(it->second.state));
  auto scene = scene_jobs_.find(it->second.scene_id);
  if (scene != scene_jobs_.end()) {
    auto& list = scene->second;
    list.erase(std::remove(list.begin(), list.end(), &it->second), list.end());
    if (list.empty()) scene_jobs_.erase(scene);
  }
  origins_.erase(id);
  runs_here_.erase(id);
  jobs_.erase(it);
}

std::vector<std::string> JobRecords::sceneJobs(const std::string& scene_id) const {
  std::vector<std::string> out;
  const auto found = scene_jobs_.find(scene_id);
  if (found == scene_jobs_.end()) return out;
  for (const JobRecord* j : found->second) out.push_back(j->id);
  return out;
}

}  // namespace rdm
