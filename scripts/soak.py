#!/usr/bin/env python3
"""Soak of the bake daemon (docs/deploy.md, "Soak"): for a fixed time, client threads mix
uploads, PATCHes, bakes, plain polls, downloads, cancels and deletes (of finished jobs, of
scenes with `?jobs=delete` or without, of older scene versions), poller threads hold long
polls (`GET /v1/jobs/{id}?wait=S[&passes=N]`, S up to 30 s), a probe thread reads /healthz
every 100 ms, and a chaos thread SIGKILLs or SIGTERMs the daemon at random moments and
restarts it on the same data directory and port. The daemon runs with a retention limit
(`--max-data-bytes`, from --max-data-mb) so that retention expires jobs during the run.
The soak keeps at most --max-scenes scenes: past it, an upload becomes a scene delete.
Then it waits for every job, stops the daemon with SIGTERM and starts it again (retention's
pass at start sees no fetch grace, which lives in memory), and checks that
  - nothing acknowledged was lost: every scene and job the daemon answered 2xx for exists,
    unless the soak deleted it (a 2xx DELETE, or a DELETE whose answer a kill cut off and
    that the log or the trash shows done) or retention expired it (an `expired` line in
    serve.log, or its directory in `jobs/.trash-*` when the daemon was killed), and an
    expired job was seen finished (its end in the log, an answer, or a cancel sent);
  - retention never expired the newest succeeded full or exact job of a scene (the next
    incremental job's default base);
  - every job ends, no job failed (serve.log included, for jobs gone since) but those
    quarantined after two deaths of the daemon (docs/api.md, "Quarantine"; counted), and
    every acknowledged cancel ended cancelled;
  - no answer was a 5xx, and the daemon never exited by itself (a watchdog restarts it and
    counts the crash; serve.log's lines that are not JSON are summarised);
  - every SIGTERM stopped the daemon within --stop-bound seconds (30), with exit code 0;
  - retention acted (some job expired), and at rest after the restart the data directory
    holds at most the limit plus one job's slack (the largest job directory kept: retention
    sums the sizes once per pass, and a job's files that land after that sum wait for the
    next pass; jobs it may not expire, each scene's newest base, can also hold it above the
    limit: --max-scenes keeps those well under it); and when over the limit, no kept job is
    one that nothing pins (the newest base of its scene, or the base chain of a kept job);
  - every kept succeeded full job's atlas.exr is byte-identical to `rdm bake` of its scene
    version (saved when the bake was acknowledged), and every kept succeeded exact job's
    atlas holds the same RDMs bit for bit (`rdm diff`; its layout is incremental, so the
    bytes differ); jobs deleted or expired are skipped;
  - the daemon's RSS stayed under --max-rss-mb;
  - no temp file is left in the data directory.
It reports requests per kind and status, long-poll latency (from a job's end, or a pass,
to the answer of a poll parked before it), the p99 of /healthz, kills, terms, the worst
SIGTERM stop time and the final data bytes against the limit. Prints a summary, writes
OUT/soak.json and exits 1 when a check fails.

  python3 scripts/soak.py --rdm build/cli/rdm [--seconds 60] [--clients 4] [--pollers 4]
      [--max-data-mb 16] [--max-scenes 6] [--kill-every 1.5,4] [--term-share 0.35] [--out DIR]
"""
import argparse
import glob
import json
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import threading
import time
import urllib.error
import urllib.request
from http.client import HTTPException

TERMINAL = ("succeeded", "failed", "cancelled")


def http(url, method="GET", body=None, timeout=10):
    """(status, parsed JSON or bytes); for an error, its problem JSON (or None); status 0
    when the daemon could not be reached or the answer was cut off."""
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, method=method)
    if data is not None:
        req.add_header("Content-Type", "application/json")
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            raw = r.read()
            kind = r.headers.get("Content-Type", "")
            return r.status, json.loads(raw) if "json" in kind and raw else raw
    except urllib.error.HTTPError as e:
        try:
            return e.code, json.loads(e.read())
        except (ValueError, OSError, HTTPException):
            return e.code, None
    except (urllib.error.URLError, HTTPException, OSError, ValueError):
        return 0, None  # refused, reset, or cut off by a kill


def percentile(values, q):
    if not values:
        return None
    s = sorted(values)
    return s[min(len(s) - 1, int(q * len(s)))]


def tree_bytes(path):
    """Bytes of the regular files under path, as the daemon counts them (JobStore::dataBytes)."""
    total = 0
    for root, _, files in os.walk(path):
        for f in files:
            try:
                st = os.lstat(os.path.join(root, f))
            except OSError:
                continue  # deleted meanwhile
            if not os.path.islink(os.path.join(root, f)):
                total += st.st_size
    return total


class Daemon:
    """rdm serve on a fixed port, killed (SIGKILL) or stopped (SIGTERM) and restarted in place."""

    def __init__(self, rdm, data, port, max_data_bytes, fetch_grace, stop_bound):
        self.rdm, self.data, self.port = rdm, data, port
        self.max_data_bytes, self.fetch_grace = max_data_bytes, fetch_grace
        self.stop_bound = stop_bound
        self.proc, self.lock = None, threading.Lock()
        self.kills, self.terms, self.stop_seconds, self.max_rss_kb = 0, 0, [], 0
        self.crashes = []  # exit codes of the daemon's exits that no signal of ours caused
        self.term_exit_codes = []  # a clean stop exits 0
        self.start_error = None
        self.trashed = set()  # ids whose directory a stop left in .trash-*: deleted or expired
        self.log_path = os.path.join(os.path.dirname(data), "serve.log")
        self.log = open(self.log_path, "ab")

    def start(self):
        # Few versions besides those jobs need: the soak saves each version it bakes itself
        # (Ledger.save_version), and what retention may not expire stays well under the limit.
        args = [self.rdm, "serve", "--data-dir", self.data, "--port", str(self.port),
                "--threads", "2", "--fetch-grace", str(self.fetch_grace), "--max-versions", "2"]
        if self.max_data_bytes:
            args += ["--max-data-bytes", str(self.max_data_bytes)]
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=self.log)
        deadline = time.time() + 30
        while time.time() < deadline:
            try:
                with urllib.request.urlopen(self.url() + "/healthz", timeout=1):
                    return
            except (urllib.error.URLError, ConnectionError, OSError):
                if self.proc.poll() is not None:
                    break
                time.sleep(0.05)
        raise RuntimeError("the daemon did not come up (see serve.log)")

    def url(self):
        return "http://127.0.0.1:%d" % self.port

    def _stop(self, sig):
        """Sends sig and waits; for SIGTERM, returns the seconds the daemon took to exit (a
        daemon still running after stop_bound is SIGKILLed: the stop took 'inf')."""
        if self.note_crash():
            return None  # it had exited by itself already
        t0 = time.time()
        self.proc.send_signal(sig)
        if sig == signal.SIGKILL:
            self.proc.wait()
            self.kills += 1
            return None
        self.terms += 1
        try:
            self.term_exit_codes.append(self.proc.wait(timeout=self.stop_bound))
            took = time.time() - t0
        except subprocess.TimeoutExpired:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait()
            took = float("inf")
        self.stop_seconds.append(took)
        return took

    def note_crash(self):
        """Whether the daemon exited by itself (an abort, a crash): counted, then True."""
        code = self.proc.poll()
        if code is None or getattr(self.proc, "crash_noted", False):
            return False
        self.proc.crash_noted = True
        self.crashes.append(code)
        return True

    def watch(self, stop):
        """Restarts the daemon when it exits by itself, until stop is set."""
        while not stop.wait(0.2):
            with self.lock:
                if not stop.is_set() and self.note_crash():
                    self.note_trash()
                    try:
                        self.start()
                    except RuntimeError as e:
                        self.start_error = str(e)
                        return

    def note_trash(self):
        """Jobs and scenes whose delete (ours or retention's) a stop cut off after the rename
        to .trash-<id>: the next start removes them."""
        for sub in ("jobs", "scenes"):
            for p in glob.glob(os.path.join(self.data, sub, ".trash-*")):
                self.trashed.add(os.path.basename(p)[len(".trash-"):])

    def restart(self, sig):
        with self.lock:
            self._stop(sig)
            self.note_trash()
            self.start()

    def sample_rss(self):
        try:
            with open("/proc/%d/status" % self.proc.pid) as f:
                for line in f:
                    if line.startswith("VmRSS"):
                        self.max_rss_kb = max(self.max_rss_kb, int(line.split()[1]))
        except OSError:
            pass

    def stop(self):
        with self.lock:
            self._stop(signal.SIGTERM)
            self.note_trash()
            self.proc.crash_noted = True


class Ledger:
    """What the soak sent and what the daemon acknowledged, shared by the threads."""

    def __init__(self, out):
        self.lock = threading.Lock()
        self.versions_dir = os.path.join(out, "versions")
        os.makedirs(self.versions_dir)
        # id -> {"version": last acknowledged, "deleted": a 2xx DELETE, "delete_sent",
        #        "delete_unanswered": a DELETE whose answer a kill cut off}
        self.scenes = {}
        # id -> {"scene", "version", "mode", "state" (last seen), "deleted", "delete_sent",
        #        "delete_unanswered"}
        self.jobs = {}
        self.cancels = set()     # jobs whose cancel was acknowledged (202)
        self.requests = {}       # kind -> {status: count}
        self.conflicts = {}      # "kind status" -> a few details of 400, 409 and 422 answers
        self.server_errors = []  # (kind, status, url)
        self.end_latency = []    # seconds from a job's end to the answer of a poll parked before it
        self.pass_latency = []   # the same from a pass's publication, for ?passes=N
        self.late_polls = []     # seconds a long poll answered after its S (non-terminal answers)
        self.health_ms = []
        self.health_failures = 0

    def count(self, kind, status, url="", problem=None):
        with self.lock:
            c = self.requests.setdefault(kind, {})
            c[str(status)] = c.get(str(status), 0) + 1
            if status >= 500:
                self.server_errors.append((kind, status, url))
            if status in (400, 409, 422) and isinstance(problem, dict):
                seen = self.conflicts.setdefault("%s %d" % (kind, status), [])
                if len(seen) < 3:
                    seen.append(problem.get("detail", ""))

    def saw(self, jid, j):
        """Notes the state of a job from an answer."""
        if isinstance(j, dict) and jid in self.jobs:
            with self.lock:
                if self.jobs[jid]["state"] not in TERMINAL:
                    self.jobs[jid]["state"] = j.get("state")

    def live_scenes(self):
        with self.lock:
            return [(s, e["version"]) for s, e in self.scenes.items() if not e["deleted"]]

    def live_jobs(self):
        """(unfinished, finished) ids not deleted, as last seen."""
        with self.lock:
            live = [(j, e["state"]) for j, e in self.jobs.items() if not e["deleted"]]
        return [j for j, s in live if s not in TERMINAL], [j for j, s in live if s in TERMINAL]

    def save_version(self, url, sid, version):
        """Keeps the scene at this version for the byte-identity check (the daemon keeps
        only --max-versions of them, and the soak deletes some)."""
        path = os.path.join(self.versions_dir, "%s_v%d.json" % (sid, version))
        if os.path.exists(path):
            return
        status, scene = http(url + "/v1/scenes/%s?version=%d" % (sid, version))
        self.count("get scene", status, url)
        if status == 200:
            part = "%s.%d.part" % (path, threading.get_ident())
            with open(part, "w") as f:
                json.dump(scene, f)
            os.replace(part, path)


# ---- the load ------------------------------------------------------------------------------

def op_upload(url, ledger, rng, scenes):
    status, j = http(url + "/v1/scenes", "POST", rng.choice(scenes))
    ledger.count("upload", status, url, j)
    if status == 201:
        with ledger.lock:
            ledger.scenes[j["id"]] = {"version": j["version"], "deleted": False,
                                      "delete_sent": False, "delete_unanswered": False}
    return status


def op_patch(url, ledger, rng, sid, version):
    body = {"base_version": version, "emission_scale": round(rng.uniform(0.5, 2.0), 3)}
    status, j = http(url + "/v1/scenes/" + sid, "PATCH", body)
    ledger.count("patch", status, url, j)
    if status == 200:
        with ledger.lock:
            e = ledger.scenes[sid]
            e["version"] = max(e["version"], j["version"])
    elif status == 409:  # stale: learn the current version
        s, info = http(url + "/v1/scenes")
        ledger.count("list scenes", s, url)
        if s == 200:
            with ledger.lock:
                for e in info["scenes"]:
                    if e["id"] in ledger.scenes:
                        ledger.scenes[e["id"]]["version"] = e["version"]
    return status


def op_bake(url, ledger, rng, sid):
    mode = rng.choice(["full", "exact", "exact", "fast"])
    status, j = http(url + "/v1/scenes/%s/bakes" % sid, "POST", {"mode": mode})
    ledger.count("bake", status, url, j)
    if status == 202:
        with ledger.lock:
            ledger.jobs[j["id"]] = {"scene": sid, "version": j["scene_version"], "mode": j["mode"],
                                    "state": j["state"], "deleted": False, "delete_sent": False,
                                    "delete_unanswered": False}
        if j["mode"] != "fast":
            ledger.save_version(url, sid, j["scene_version"])
    return status


def op_delete_job(url, ledger, jid, kind):
    """DELETE /v1/jobs/{id}: 202 cancels an unfinished job, 204 deletes a finished one, 409
    names the jobs that need it (or a job writing its results), 404 when already gone."""
    with ledger.lock:
        ledger.jobs[jid]["delete_sent"] = True
    status, j = http(url + "/v1/jobs/" + jid, "DELETE")
    ledger.count(kind, status, url, j)
    with ledger.lock:
        if status == 202:
            ledger.cancels.add(jid)
            if isinstance(j, dict) and j.get("state") in TERMINAL:
                ledger.jobs[jid]["state"] = j["state"]
        elif status == 204:
            ledger.jobs[jid]["deleted"] = True
        elif status == 0:
            ledger.jobs[jid]["delete_unanswered"] = True  # it may have been deleted
    return status


def op_delete_scene(url, ledger, rng, sid):
    """DELETE /v1/scenes/{id}[?jobs=delete]: 204, or 409 while it has unfinished jobs (or
    kept ones, without ?jobs=delete)."""
    with_jobs = rng.random() < 0.75
    with ledger.lock:
        ledger.scenes[sid]["delete_sent"] = True
        for e in ledger.jobs.values():
            if e["scene"] == sid:
                e["delete_sent"] = True
    status, j = http(url + "/v1/scenes/" + sid + ("?jobs=delete" if with_jobs else ""), "DELETE")
    ledger.count("delete scene" + ("?jobs=delete" if with_jobs else ""), status, url, j)
    with ledger.lock:
        if status in (0, 204):  # 0: the answer was lost, it may have been deleted
            ledger.scenes[sid]["deleted" if status else "delete_unanswered"] = True
            for e in ledger.jobs.values():  # 204: none was unfinished, the kept ones went with it
                if e["scene"] == sid:
                    e["deleted" if status else "delete_unanswered"] = True
    return status


def op_delete_version(url, ledger, rng, sid, version):
    """DELETE /v1/scenes/{id}/versions/{n} of an older version: 204, 409 when a job needs
    it, 404 when the daemon dropped it already (--max-versions)."""
    if version < 2:
        return None
    n = rng.randint(max(1, version - 10), version - 1)
    status, j = http(url + "/v1/scenes/%s/versions/%d" % (sid, n), "DELETE")
    ledger.count("delete version", status, url, j)
    return status


def client(daemon, ledger, scenes, stop, seed, max_scenes):
    """One client: a random request at a time; a short pause while the daemon is down."""
    rng = random.Random(seed)
    while not stop.is_set():
        url = daemon.url()
        live = ledger.live_scenes()
        unfinished, finished = ledger.live_jobs()
        op = rng.choices(
            ["upload", "patch", "bake", "poll", "download", "cancel", "delete job",
             "delete scene", "delete version"],
            [3, 20, 30, 15, 10, 8, 3, 1, 3])[0]
        if op == "upload" and len(live) >= max_scenes:
            op = "delete scene" if rng.random() < 0.25 else "bake"  # scenes live a while
        status = None
        if op == "upload" or not live:
            status = op_upload(url, ledger, rng, scenes)
        elif op == "patch":
            status = op_patch(url, ledger, rng, *rng.choice(live))
        elif op == "bake":
            status = op_bake(url, ledger, rng, rng.choice(live)[0])
        elif op == "poll" and (unfinished or finished):
            jid = rng.choice(unfinished or finished)
            status, j = http(url + "/v1/jobs/" + jid)
            ledger.count("poll", status, url)
            ledger.saw(jid, j)
        elif op == "download" and finished:
            status, _ = http(url + "/v1/jobs/" + rng.choice(finished) + "/index.json")
            ledger.count("download", status, url)
        elif op == "cancel" and unfinished:
            status = op_delete_job(url, ledger, rng.choice(unfinished), "cancel")
        elif op == "delete job" and finished:
            status = op_delete_job(url, ledger, rng.choice(finished), "delete job")
        elif op == "delete scene":
            status = op_delete_scene(url, ledger, rng, rng.choice(live)[0])
        elif op == "delete version":
            status = op_delete_version(url, ledger, rng, *rng.choice(live))
        if status == 0:
            time.sleep(0.1)  # the daemon is restarting


def poller(daemon, ledger, stop, seed):
    """Long polls of unfinished jobs. Latency: from the job's end (its `finished`) or the
    pass's publication to the answer, for polls sent before it."""
    rng = random.Random(seed)
    while not stop.is_set():
        unfinished, finished = ledger.live_jobs()
        if not unfinished and not finished:
            time.sleep(0.05)
            continue
        jid = rng.choice(unfinished or finished)
        wait = rng.randint(1, 30)
        passes = rng.choice([None, None, 1, 2])
        q = "?wait=%d" % wait + ("&passes=%d" % passes if passes else "")
        sent = time.time()
        status, j = http(daemon.url() + "/v1/jobs/" + jid + q, timeout=wait + 15)
        got = time.time()
        ledger.count("long poll", status, daemon.url())
        if status == 0:
            time.sleep(0.1)  # the daemon is restarting
        if status != 200 or not isinstance(j, dict):
            continue
        ledger.saw(jid, j)
        try:
            note_poll_latency(ledger, j, sent, got, wait, passes)
        except (KeyError, IndexError, TypeError):
            ledger.count("long poll (unexpected body)", 200)


def note_poll_latency(ledger, j, sent, got, wait, passes):
    """A poll sent before the job ended (or the pass came) answered `got - end` after it."""
    with ledger.lock:
        if j["state"] in TERMINAL and j.get("finished", 0) > sent:
            ledger.end_latency.append(got - j["finished"])
        elif passes and j["passes"]["done"] >= passes and j["state"] not in TERMINAL:
            published = j["created"] + j["passes"]["published_seconds"][passes - 1]
            if published > sent:
                ledger.pass_latency.append(got - published)
        elif j["state"] not in TERMINAL and (not passes or j["passes"]["done"] < passes):
            ledger.late_polls.append(got - sent - wait)  # should be about 0 (or < 0: a SIGTERM)


def health_probe(daemon, ledger, stop):
    """GET /healthz every 100 ms; the latency of each 200."""
    while not stop.wait(0.1):
        t0 = time.time()
        status, _ = http(daemon.url() + "/healthz", timeout=5)
        with ledger.lock:
            if status == 200:
                ledger.health_ms.append((time.time() - t0) * 1000)
            else:
                ledger.health_failures += 1  # during restarts


def chaos(daemon, stop, seed, low, high, term_share):
    """SIGKILLs or (term_share of the time) SIGTERMs the daemon, then restarts it."""
    rng = random.Random(seed)
    while not stop.wait(rng.uniform(low, high)):
        try:
            daemon.restart(signal.SIGTERM if rng.random() < term_share else signal.SIGKILL)
        except RuntimeError as e:
            daemon.start_error = str(e)
            return


# ---- the checks ----------------------------------------------------------------------------

def wait_all(daemon, ledger, limit_s):
    """Waits until every job not deleted ended (or answers 404)."""
    deadline = time.time() + limit_s
    for jid, e in list(ledger.jobs.items()):
        while not e["deleted"] and e["state"] not in TERMINAL and time.time() < deadline:
            status, j = http(daemon.url() + "/v1/jobs/%s?wait=10" % jid, timeout=20)
            if status == 404:
                break
            ledger.saw(jid, j)


def read_log(path):
    """serve.log's job and scene events: per job its queue order (seq), scene, mode and the
    states logged; deleted scenes."""
    jobs, scenes_deleted, seq, other = {}, set(), 0, {}
    quarantine = re.compile(r"rdm serve: job (j[0-9a-f]{16}): .*quarantined")
    with open(path, "rb") as f:
        for raw in f:
            if not raw.startswith(b"{"):
                line = raw.decode(errors="replace").strip()
                q = quarantine.match(line)
                if q:  # failed at start after two deaths (docs/api.md, "Quarantine")
                    jobs.setdefault(q.group(1), {"seq": None, "scene": None, "mode": None,
                                                 "states": []})["states"].append("quarantined")
                elif not line.startswith("listening on"):
                    key = re.sub(r"\b[js][0-9a-f]{16}\b|\d+", "N", line)[:200]
                    other[key] = other.get(key, 0) + 1
                continue
            try:
                e = json.loads(raw)
            except ValueError:
                continue  # a line a SIGKILL cut
            if e.get("event") == "job" and "id" in e:
                j = jobs.setdefault(e["id"], {"seq": None, "scene": e.get("scene"),
                                              "mode": e.get("mode"), "states": []})
                if e.get("state") == "queued" and j["seq"] is None:
                    seq += 1
                    j["seq"] = seq
                j["scene"], j["mode"] = j["scene"] or e.get("scene"), j["mode"] or e.get("mode")
                state = e.get("state")
                # failed at start after two deaths (docs/api.md, "Quarantine")
                if state == "failed" and "quarantined, not resumed" in (e.get("reason") or ""):
                    state = "quarantined"
                j["states"].append(state)
                if state == "failed":
                    j["reason"] = e.get("reason")
            elif e.get("event") == "scene" and e.get("state") == "deleted" and "version" not in e:
                scenes_deleted.add(e.get("id"))
    return jobs, scenes_deleted, other


def settle_data(daemon, limit_s=30):
    """Bytes of the data directory once retention's pass at start is done (no change for 2 s)."""
    last, same, deadline = -1, 0, time.time() + limit_s
    while time.time() < deadline and same < 4:
        time.sleep(0.5)
        now = tree_bytes(daemon.data)
        same = same + 1 if now == last else 0
        last = now
    return last


def retention_leftovers(url):
    """At rest over the limit, retention must have expired every finished job it may: those
    kept that are not, as far as the API shows, pinned (the newest succeeded full or exact job
    of its scene, or on the base chain of a kept succeeded job: its origins are there).
    Returns [(id, state)] of kept jobs nothing pins, or None when the list failed."""
    jobs, next_url = [], "/v1/jobs?limit=100"
    while next_url:
        status, page = http(url + next_url)
        if status != 200:
            return None
        jobs += page["jobs"]
        next_url = page["next"]
    by_id, pinned, newest = {j["id"]: j for j in jobs}, set(), set()
    for j in jobs:  # newest first
        if j["state"] == "succeeded" and j["mode"] != "fast" and j["scene"] not in newest:
            newest.add(j["scene"])
            pinned.add(j["id"])
        if j["state"] == "succeeded":
            base = j.get("base_job")
            while base and base in by_id and base not in pinned:
                pinned.add(base)
                base = by_id[base].get("base_job")
    return [(j["id"], j["state"]) for j in jobs if j["id"] not in pinned]


def account(daemon, ledger, log_jobs, log_scenes_deleted):
    """The fate of every acknowledged scene and job after the final restart: kept (with its
    final state), deleted, expired, or lost. Returns (final states, fates, problems)."""
    url, problems, final, fates = daemon.url(), [], {}, {}
    for sid, e in ledger.scenes.items():
        status, _ = http(url + "/v1/scenes/" + sid)
        if status == 200:
            if e["deleted"]:
                problems.append("scene %s: its DELETE was acknowledged (204), it still exists"
                                % sid)
            continue
        if status != 404:
            problems.append("scene %s: GET answered %d" % (sid, status))
        elif not (e["deleted"] or sid in log_scenes_deleted or e["delete_unanswered"] or
                  (e["delete_sent"] and sid in daemon.trashed)):
            problems.append("scene %s was acknowledged and is gone, not deleted" % sid)
    for jid, e in ledger.jobs.items():
        status, j = http(url + "/v1/jobs/" + jid)
        states = log_jobs.get(jid, {}).get("states", [])
        if status == 200:
            final[jid] = j
            fates[jid] = "kept"
            if e["deleted"]:
                problems.append("job %s: its delete was acknowledged (204), it still exists" % jid)
            continue
        if status != 404:
            problems.append("job %s: GET answered %d" % (jid, status))
            continue
        if e["deleted"] or "deleted" in states or e["delete_unanswered"] or \
                (e["delete_sent"] and jid in daemon.trashed):
            fates[jid] = "deleted"
        elif "expired" in states or jid in daemon.trashed:
            fates[jid] = "expired"
            seen_end = (e["state"] in TERMINAL or e["delete_sent"] or
                        any(s in TERMINAL + ("quarantined",) for s in states))
            if not seen_end:
                problems.append("job %s expired but was never seen finished" % jid)
        else:
            fates[jid] = "lost"
            problems.append("job %s was acknowledged and is gone, neither deleted nor expired"
                            " (log: %s)" % (jid, ", ".join(states) or "no line"))
    return final, fates, problems


def check_newest(ledger, log_jobs, final, fates):
    """Retention spares each scene's newest succeeded full or exact job (by submission): for
    every scene, the newest such job must not have expired. Scenes whose newer jobs' ends are
    unknown (gone without a logged or seen state, or no queue line) are skipped."""
    problems, by_scene = [], {}
    for jid, lj in log_jobs.items():
        if lj["scene"]:
            by_scene.setdefault(lj["scene"], []).append(jid)
    for sid, jids in by_scene.items():
        if sid in ledger.scenes and ledger.scenes[sid]["deleted"]:
            continue
        known, unknown_seq = [], False
        for jid in jids:
            lj = log_jobs[jid]
            if lj["seq"] is None:
                unknown_seq = True
                continue
            state = (final.get(jid) or {}).get("state") or ledger.jobs.get(jid, {}).get("state")
            ended = [s for s in lj["states"] if s in TERMINAL]
            known.append((lj["seq"], jid, lj["mode"], state if state in TERMINAL else
                          (ended[-1] if ended else None)))
        if unknown_seq:
            continue
        known.sort(reverse=True)
        for seq, jid, mode, state in known:
            gone = "deleted" in log_jobs[jid]["states"] or fates.get(jid) == "deleted"
            if mode not in ("full", "exact"):
                continue
            if state is None or gone:
                break  # a newer one may have succeeded, or the soak deleted it: skip the scene
            if state == "succeeded":
                if fates.get(jid) == "expired" or "expired" in log_jobs[jid]["states"]:
                    problems.append("job %s, the newest succeeded %s job of scene %s, expired"
                                    % (jid, mode, sid))
                break
    return problems


def check_data_size(daemon, limit, data_bytes, peak_bytes, log_jobs):
    """Retention acted, and at rest the data directory is within the limit plus one job's
    slack (the largest job directory kept); over the limit, only pinned jobs are kept."""
    problems = []
    job_bytes = [tree_bytes(p) for p in glob.glob(os.path.join(daemon.data, "jobs", "j*"))]
    slack = max(job_bytes, default=0)
    expired = sum(1 for lj in log_jobs.values() if "expired" in lj["states"])
    size = {"data_bytes_at_rest": data_bytes, "data_limit_bytes": limit, "slack_bytes": slack,
            "data_bytes_peak": peak_bytes, "jobs_kept_at_rest": len(job_bytes),
            "expired_logged": expired}
    if not limit:
        return size, problems
    if data_bytes > limit + slack:
        problems.append("the data directory holds %d bytes at rest, over the limit %d plus one "
                        "job's slack %d (%d jobs kept, %d bytes of them; scenes %d bytes)"
                        % (data_bytes, limit, slack, len(job_bytes), sum(job_bytes),
                           tree_bytes(os.path.join(daemon.data, "scenes"))))
    if not expired:
        problems.append("retention never acted (the data directory peaked at %d bytes, limit %d): "
                        "lower --max-data-mb or run longer" % (peak_bytes, limit))
    if data_bytes > limit:
        unpinned = retention_leftovers(daemon.url())
        if unpinned:
            problems.append("at rest over the limit (%d > %d bytes), retention kept %d jobs that "
                            "nothing pins: %s" % (data_bytes, limit, len(unpinned), unpinned[:5]))
    return size, problems


def check_job_ends(ledger, log_jobs, final):
    """Every job ended, none failed but those quarantined after two deaths of the daemon
    (expected under SIGKILLs; counted), every acknowledged cancel ended cancelled."""
    problems = []
    quarantined = sorted(j for j, lj in log_jobs.items() if "quarantined" in lj["states"])
    for jid, lj in log_jobs.items():
        if "failed" in lj["states"]:
            problems.append("job %s failed: %s" % (jid, lj.get("reason")))
    for jid, e in ledger.jobs.items():
        j = final.get(jid)
        if j and j["state"] not in TERMINAL:
            problems.append("job %s never ended (%s)" % (jid, j["state"]))
        elif j and j["state"] == "failed" and "quarantined" not in (j.get("error") or "") \
                and "failed" not in log_jobs.get(jid, {}).get("states", []):
            problems.append("job %s failed: %s" % (jid, j.get("error")))
        if jid in ledger.cancels:
            ended = (j or {}).get("state") or e["state"]
            if ended in TERMINAL and ended != "cancelled":
                problems.append("job %s: its cancel was acknowledged, it ended %s" % (jid, ended))
    return quarantined, problems


def check_stops(daemon, bound):
    """Every SIGTERM (the final one included) stopped the daemon within bound, exit code 0."""
    problems = []
    worst = max(daemon.stop_seconds, default=0.0)
    if worst > bound:
        problems.append("a SIGTERM took %.1f s to stop the daemon (bound %.0f s)" % (worst, bound))
    if any(daemon.term_exit_codes):
        problems.append("SIGTERM exit codes %s (a clean stop exits 0)" % daemon.term_exit_codes)
    return problems


def summarize(a, daemon, ledger, fates, final, size, quarantined, stderr_other, checked,
              no_reference, problems):
    states, fate_counts = {}, {}
    for jid, f in fates.items():
        fate_counts[f] = fate_counts.get(f, 0) + 1
        if f == "kept":
            states[final[jid]["state"]] = states.get(final[jid]["state"], 0) + 1
    return dict({
        "seconds": a.seconds, "clients": a.clients, "pollers": a.pollers,
        "kills": daemon.kills, "terms": daemon.terms, "crashes": len(daemon.crashes),
        "worst_sigterm_stop_s": round(max(daemon.stop_seconds, default=0.0), 2),
        "sigterm_stops_s": [round(s, 2) for s in daemon.stop_seconds],
        "requests": ledger.requests,
        "conflicts_sample": ledger.conflicts,
        "long_poll_after_end": latency_summary(ledger.end_latency),
        "long_poll_after_pass": latency_summary(ledger.pass_latency),
        "long_poll_late_max_s": round(max(ledger.late_polls, default=0.0), 2),
        "healthz": dict(latency_summary(ledger.health_ms, 1.0) or {},
                        failed_during_restarts=ledger.health_failures),
        "scenes": len(ledger.scenes),
        "scenes_deleted": sum(1 for e in ledger.scenes.values() if e["deleted"]),
        "jobs": len(ledger.jobs), "job_fates": fate_counts, "kept_job_states": states,
        "quarantined": len(quarantined),
        "trashed_at_stops": sorted(daemon.trashed),
        "stderr_not_json": stderr_other}, **size,
        atlases_checked=checked, atlases_without_reference=no_reference,
        max_rss_mb=round(daemon.max_rss_kb / 1024, 1), problems=problems)


def fetch_atlas(url, jid, out):
    os.makedirs(out, exist_ok=True)
    status, index = http(url + "/v1/jobs/%s/index.json" % jid)
    if status != 200:
        return status
    with open(os.path.join(out, "index.json"), "w") as f:
        json.dump(index, f)
    for p in range(len(index["pages"])):
        status, data = http(url + "/v1/jobs/%s/atlas.exr?page=%d" % (jid, p), timeout=60)
        if status != 200:
            return status
        with open(os.path.join(out, "atlas.exr" if p == 0 else "atlas.page%d.exr" % p), "wb") as f:
            f.write(data)
    return 200


def check_atlases(rdm, daemon, ledger, final, out):
    """Kept succeeded full and exact jobs against `rdm bake` of their scene version."""
    problems, refs, checked, no_reference = [], {}, 0, 0
    for jid, meta in ledger.jobs.items():
        j = final.get(jid)
        if not j or j["state"] != "succeeded" or meta["mode"] == "fast":
            continue
        key = (meta["scene"], meta["version"])
        if key not in refs:
            path = os.path.join(ledger.versions_dir, "%s_v%d.json" % key)
            if not os.path.exists(path):
                ledger.save_version(daemon.url(), *key)
            if not os.path.exists(path):
                no_reference += 1  # not saved at the bake's answer, and gone from the daemon
                continue
            ref = os.path.join(out, "ref", "%s_v%d" % key)
            os.makedirs(os.path.dirname(ref), exist_ok=True)
            subprocess.run([rdm, "bake", "--scene", path, "--quiet", "-o", ref], check=True,
                           stdout=subprocess.DEVNULL)
            refs[key] = ref
        got = os.path.join(out, "jobs", jid)
        status = fetch_atlas(daemon.url(), jid, got)
        if status != 200:
            problems.append("job %s: its atlas could not be downloaded (%d)" % (jid, status))
            continue
        checked += 1
        if meta["mode"] == "full":
            with open(os.path.join(got, "atlas.exr"), "rb") as a, \
                    open(os.path.join(refs[key], "atlas.exr"), "rb") as b:
                if a.read() != b.read():
                    problems.append("job %s (full): atlas.exr differs from rdm bake" % jid)
        elif subprocess.run([rdm, "diff", got, refs[key]], stdout=subprocess.DEVNULL).returncode:
            problems.append("job %s (exact): RDMs differ from rdm bake" % jid)
    return checked, no_reference, problems


def temp_files(data):
    found = []
    for root, _, files in os.walk(data):
        found += [os.path.join(root, f) for f in files if ".tmp" in f]
    return found


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def latency_summary(values, scale=1000.0):
    """p50 / p99 / max in ms."""
    if not values:
        return None
    return {"n": len(values), "p50_ms": round(percentile(values, 0.5) * scale, 1),
            "p99_ms": round(percentile(values, 0.99) * scale, 1),
            "max_ms": round(max(values) * scale, 1)}


def make_scenes(rdm, out):
    scenes = []
    for name in ("chess", "island"):
        path = os.path.join(out, name + ".json")
        subprocess.run([rdm, "scene", "--scene", name, "-o", path], check=True,
                       stdout=subprocess.DEVNULL)
        with open(path) as f:
            scene = json.load(f)
        scene["bake"].update({"spp": 1, "max_hemisphere": 4})  # bakes of a fraction of a second
        scenes.append(scene)
    return scenes


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rdm", required=True)
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--clients", type=int, default=4)
    ap.add_argument("--pollers", type=int, default=4, help="long-poll threads")
    ap.add_argument("--kill-every", default="1.5,4", help="seconds between stops, LOW,HIGH")
    ap.add_argument("--term-share", type=float, default=0.35, help="stops that are SIGTERM")
    ap.add_argument("--stop-bound", type=float, default=30, help="seconds a SIGTERM may take")
    ap.add_argument("--max-data-mb", type=float, default=16,
                    help="rdm serve --max-data-bytes, MiB (0: no limit, no size check)")
    ap.add_argument("--fetch-grace", type=int, default=5, help="rdm serve --fetch-grace")
    ap.add_argument("--max-scenes", type=int, default=6, help="scenes the soak keeps at once")
    ap.add_argument("--max-rss-mb", type=float, default=1024)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="/tmp/rdm-soak")
    a = ap.parse_args()
    thread_errors = []  # a soak thread that died: the load was short of it (a script bug)

    def on_thread_error(args):
        thread_errors.append("%s: %r" % (args.thread.name, args.exc_value))
        threading.__excepthook__(args)
    threading.excepthook = on_thread_error
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(a.out)
    scenes = make_scenes(a.rdm, a.out)
    limit = int(a.max_data_mb * 1024 * 1024)
    daemon = Daemon(a.rdm, os.path.join(a.out, "data"), free_port(), limit, a.fetch_grace,
                    a.stop_bound)
    daemon.start()
    ledger, stop, probe_stop = Ledger(a.out), threading.Event(), threading.Event()
    low, high = (float(x) for x in a.kill_every.split(","))
    threads = [threading.Thread(target=client, args=(daemon, ledger, scenes, stop, a.seed + i,
                                                     a.max_scenes))
               for i in range(a.clients)]
    threads += [threading.Thread(target=poller, args=(daemon, ledger, stop, a.seed + 100 + i))
                for i in range(a.pollers)]
    threads.append(threading.Thread(target=chaos, args=(daemon, stop, a.seed, low, high,
                                                        a.term_share)))
    probe = threading.Thread(target=health_probe, args=(daemon, ledger, probe_stop))
    watch_stop = threading.Event()
    watchdog = threading.Thread(target=daemon.watch, args=(watch_stop,))
    for t in threads + [probe, watchdog]:
        t.start()
    end, peak_bytes = time.time() + a.seconds, 0
    while time.time() < end and not daemon.start_error:
        daemon.sample_rss()
        peak_bytes = max(peak_bytes, tree_bytes(daemon.data))
        time.sleep(0.5)
    stop.set()
    for t in threads:
        t.join()
    if daemon.start_error:
        print("problems: 1\n  %s; the end of serve.log:" % daemon.start_error)
        with open(daemon.log_path, "rb") as f:
            print(b"".join(f.readlines()[-20:]).decode(errors="replace"))
        probe_stop.set()
        watch_stop.set()
        return 1
    wait_all(daemon, ledger, 300)
    probe_stop.set()
    probe.join()

    # At rest: a clean stop and start; retention's pass at start sees no fetch grace.
    daemon.restart(signal.SIGTERM)
    data_bytes = settle_data(daemon)
    log_jobs, log_scenes_deleted, stderr_other = read_log(daemon.log_path)
    final, fates, problems = account(daemon, ledger, log_jobs, log_scenes_deleted)
    size, size_problems = check_data_size(daemon, limit, data_bytes, peak_bytes, log_jobs)
    problems += size_problems
    problems += check_newest(ledger, log_jobs, final, fates)
    quarantined, end_problems = check_job_ends(ledger, log_jobs, final)
    problems += end_problems
    problems += ["%s answered %d: %s" % err for err in ledger.server_errors]
    problems += ["soak thread died (a bug of this script): " + e for e in thread_errors]
    if daemon.crashes:
        problems.append("the daemon exited by itself %d times (exit codes %s); its stderr lines "
                        "that are not JSON: %s" % (len(daemon.crashes), sorted(set(daemon.crashes)),
                                                   json.dumps(stderr_other)))
    checked, no_reference, atlas_problems = check_atlases(a.rdm, daemon, ledger, final, a.out)
    problems += atlas_problems
    daemon.sample_rss()
    watch_stop.set()
    watchdog.join()
    daemon.stop()
    problems += check_stops(daemon, a.stop_bound)
    problems += ["temp file left: " + f for f in temp_files(daemon.data)]
    if daemon.max_rss_kb / 1024 > a.max_rss_mb:
        problems.append("RSS reached %.0f MB" % (daemon.max_rss_kb / 1024))
    summary = summarize(a, daemon, ledger, fates, final, size, quarantined, stderr_other,
                        checked, no_reference, problems)
    with open(os.path.join(a.out, "soak.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print(json.dumps({k: v for k, v in summary.items()
                      if k not in ("problems", "sigterm_stops_s", "conflicts_sample",
                                   "trashed_at_stops", "stderr_not_json")}))
    print("problems: %d%s" % (len(problems), "".join("\n  " + p for p in problems[:30])))
    return 1 if problems else 0


if __name__ == "__main__":
    raise SystemExit(main())
