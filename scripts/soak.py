#!/usr/bin/env python3
"""Soak of the bake daemon (docs/deploy.md, "Soak"): concurrent clients mix uploads, PATCHes,
bakes, polls, downloads and cancels for a fixed time while the daemon is SIGKILLed and
restarted at random moments. Then it checks that
  - nothing acknowledged was lost: every scene and job the daemon answered 2xx for exists,
    every job ends, no job failed, and every acknowledged cancel ended cancelled;
  - every succeeded full job's atlas.exr is byte-identical to `rdm bake` of its scene
    version, and every succeeded exact job's atlas holds the same RDMs bit for bit
    (`rdm diff`; its layout is incremental, so the bytes differ);
  - the daemon's RSS stayed under --max-rss-mb;
  - no temp file is left in the data directory.
Prints a summary, writes OUT/soak.json and exits 1 when a check fails.

  python3 scripts/soak.py --rdm build/cli/rdm [--seconds 60] [--clients 4] [--out DIR]
"""
import argparse
import json
import os
import random
import shutil
import signal
import socket
import subprocess
import threading
import time
import urllib.error
import urllib.request


class Daemon:
    """rdm serve on a fixed port, killed and restarted in place."""

    def __init__(self, rdm, data, port):
        self.rdm, self.data, self.port = rdm, data, port
        self.proc, self.lock, self.kills, self.max_rss_kb = None, threading.Lock(), 0, 0
        self.log = open(os.path.join(os.path.dirname(data), "serve.log"), "ab")

    def start(self):
        # Every version stays, so each job's scene can be baked again for the check.
        self.proc = subprocess.Popen(
            [self.rdm, "serve", "--data-dir", self.data, "--port", str(self.port),
             "--threads", "2", "--max-versions", "1000000"], stdout=self.log, stderr=self.log)
        deadline = time.time() + 30
        while time.time() < deadline:
            try:
                with urllib.request.urlopen(self.url() + "/healthz", timeout=1):
                    return
            except (urllib.error.URLError, ConnectionError, OSError):
                time.sleep(0.05)
        raise RuntimeError("the daemon did not come up")

    def url(self):
        return "http://127.0.0.1:%d" % self.port

    def kill_and_restart(self):
        with self.lock:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait()
            self.kills += 1
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
        self.proc.send_signal(signal.SIGTERM)
        self.proc.wait(timeout=30)


def http(url, method="GET", body=None, timeout=10):
    """(status, parsed JSON or bytes); status 0 when the daemon could not be reached."""
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, method=method)
    if data is not None:
        req.add_header("Content-Type", "application/json")
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            raw = r.read()
            kind = r.headers.get("Content-Type", "")
            return r.status, json.loads(raw) if "json" in kind else raw
    except urllib.error.HTTPError as e:
        return e.code, None
    except (urllib.error.URLError, ConnectionError, OSError, ValueError):
        return 0, None


class Ledger:
    """What the daemon acknowledged (a 2xx answer), shared by the clients."""

    def __init__(self):
        self.lock = threading.Lock()
        self.scenes = {}   # id -> current version as last acknowledged
        self.jobs = {}     # id -> {"scene", "version", "mode"}
        self.cancels = set()
        self.ops = {}      # op -> [acknowledged, refused, unreachable]

    def count(self, op, status):
        with self.lock:
            c = self.ops.setdefault(op, [0, 0, 0])
            c[0 if 200 <= status < 300 else (2 if status == 0 else 1)] += 1


def client(daemon, ledger, scenes, stop, seed):
    rng = random.Random(seed)
    while not stop.is_set():
        url = daemon.url()
        with ledger.lock:
            scene_ids = list(ledger.scenes.items())
            job_ids = list(ledger.jobs)
        op = rng.choices(["upload", "patch", "bake", "poll", "download", "cancel"],
                         [5, 25, 25, 25, 10, 10])[0]
        if op == "upload" or not scene_ids:
            status, j = http(url + "/v1/scenes", "POST", rng.choice(scenes))
            ledger.count("upload", status)
            if status == 201:
                with ledger.lock:
                    ledger.scenes[j["id"]] = j["version"]
        elif op == "patch":
            sid, version = rng.choice(scene_ids)
            body = {"base_version": version, "emission_scale": round(rng.uniform(0.5, 2.0), 3)}
            status, j = http(url + "/v1/scenes/" + sid, "PATCH", body)
            ledger.count("patch", status)
            if status == 200:
                with ledger.lock:
                    ledger.scenes[sid] = max(ledger.scenes[sid], j["version"])
            elif status == 409:  # stale: learn the current version
                s, info = http(url + "/v1/scenes")
                if s == 200:
                    with ledger.lock:
                        for e in info["scenes"]:
                            if e["id"] in ledger.scenes:
                                ledger.scenes[e["id"]] = e["version"]
        elif op == "bake":
            sid, _ = rng.choice(scene_ids)
            mode = rng.choice(["full", "exact", "exact", "fast"])
            status, j = http(url + "/v1/scenes/%s/bakes" % sid, "POST", {"mode": mode})
            ledger.count("bake", status)
            if status == 202:
                with ledger.lock:
                    ledger.jobs[j["id"]] = {"scene": sid, "version": j["scene_version"],
                                            "mode": j["mode"]}
        elif op == "poll" and job_ids:
            status, _ = http(url + "/v1/jobs/" + rng.choice(job_ids) + "?wait=1", timeout=15)
            ledger.count("poll", status)
        elif op == "download" and job_ids:
            status, _ = http(url + "/v1/jobs/" + rng.choice(job_ids) + "/index.json")
            ledger.count("download", status if status != 409 else 200)  # 409: not done yet
        elif op == "cancel" and job_ids:
            jid = rng.choice(job_ids)
            status, _ = http(url + "/v1/jobs/" + jid, "DELETE")
            ledger.count("cancel", status)
            if 200 <= status < 300:
                with ledger.lock:
                    ledger.cancels.add(jid)


def killer(daemon, stop, seed, low, high):
    rng = random.Random(seed)
    while not stop.wait(rng.uniform(low, high)):
        daemon.kill_and_restart()


def wait_all(daemon, ledger, limit_s):
    deadline = time.time() + limit_s
    final = {}
    for jid in ledger.jobs:
        while time.time() < deadline:
            status, j = http(daemon.url() + "/v1/jobs/%s?wait=10" % jid, timeout=20)
            if status == 200 and j["state"] not in ("queued", "running"):
                final[jid] = j
                break
            if status == 404:
                final[jid] = None
                break
    return final


def fetch_atlas(url, jid, out):
    os.makedirs(out, exist_ok=True)
    status, index = http(url + "/v1/jobs/%s/index.json" % jid)
    if status != 200:
        return False
    with open(os.path.join(out, "index.json"), "w") as f:
        json.dump(index, f)
    for p in range(len(index["pages"])):
        status, data = http(url + "/v1/jobs/%s/atlas.exr?page=%d" % (jid, p), timeout=60)
        if status != 200:
            return False
        with open(os.path.join(out, "atlas.exr" if p == 0 else "atlas.page%d.exr" % p), "wb") as f:
            f.write(data)
    return True


def check_atlases(rdm, daemon, ledger, final, out):
    problems, refs, checked = [], {}, 0
    for jid, meta in ledger.jobs.items():
        j = final.get(jid)
        if not j or j["state"] != "succeeded" or meta["mode"] == "fast":
            continue
        key = (meta["scene"], meta["version"])
        if key not in refs:
            status, scene = http(daemon.url() + "/v1/scenes/%s?version=%d" % key)
            if status != 200:
                problems.append("scene %s version %d unreadable (%d)" % (key + (status,)))
                continue
            ref = os.path.join(out, "ref", "%s_v%d" % key)
            path = ref + ".json"
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as f:
                json.dump(scene, f)
            subprocess.run([rdm, "bake", "--scene", path, "--quiet", "-o", ref], check=True,
                           stdout=subprocess.DEVNULL)
            refs[key] = ref
        got = os.path.join(out, "jobs", jid)
        if not fetch_atlas(daemon.url(), jid, got):
            problems.append("job %s: its atlas could not be downloaded" % jid)
            continue
        checked += 1
        if meta["mode"] == "full":
            with open(os.path.join(got, "atlas.exr"), "rb") as a, \
                    open(os.path.join(refs[key], "atlas.exr"), "rb") as b:
                if a.read() != b.read():
                    problems.append("job %s (full): atlas.exr differs from rdm bake" % jid)
        elif subprocess.run([rdm, "diff", got, refs[key]], stdout=subprocess.DEVNULL).returncode:
            problems.append("job %s (exact): RDMs differ from rdm bake" % jid)
    return checked, problems


def temp_files(data):
    found = []
    for root, _, files in os.walk(data):
        found += [os.path.join(root, f) for f in files if ".tmp" in f]
    return found


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rdm", required=True)
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--clients", type=int, default=4)
    ap.add_argument("--kill-every", default="1.5,4", help="seconds between SIGKILLs, LOW,HIGH")
    ap.add_argument("--max-rss-mb", type=float, default=1024)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="/tmp/rdm-soak")
    a = ap.parse_args()
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(a.out)
    scenes = []
    for name in ("chess", "island"):
        path = os.path.join(a.out, name + ".json")
        subprocess.run([a.rdm, "scene", "--scene", name, "-o", path], check=True,
                       stdout=subprocess.DEVNULL)
        with open(path) as f:
            scene = json.load(f)
        scene["bake"].update({"spp": 1, "max_hemisphere": 4})  # bakes of a fraction of a second
        scenes.append(scene)
    daemon = Daemon(a.rdm, os.path.join(a.out, "data"), free_port())
    daemon.start()
    ledger, stop = Ledger(), threading.Event()
    low, high = (float(x) for x in a.kill_every.split(","))
    threads = [threading.Thread(target=client, args=(daemon, ledger, scenes, stop, a.seed + i))
               for i in range(a.clients)]
    threads.append(threading.Thread(target=killer, args=(daemon, stop, a.seed, low, high)))
    for t in threads:
        t.start()
    end = time.time() + a.seconds
    while time.time() < end:
        daemon.sample_rss()
        time.sleep(0.5)
    stop.set()
    for t in threads:
        t.join()
    final = wait_all(daemon, ledger, 300)
    problems = []
    for sid in ledger.scenes:
        if http(daemon.url() + "/v1/scenes/" + sid)[0] != 200:
            problems.append("scene %s was acknowledged and is gone" % sid)
    for jid in ledger.jobs:
        j = final.get(jid)
        if j is None:
            problems.append("job %s was acknowledged and is gone or never ended" % jid)
        elif j["state"] == "failed":
            problems.append("job %s failed: %s" % (jid, j.get("error")))
        elif jid in ledger.cancels and j["state"] != "cancelled":
            problems.append("job %s: its cancel was acknowledged, it ended %s" % (jid, j["state"]))
    checked, atlas_problems = check_atlases(a.rdm, daemon, ledger, final, a.out)
    problems += atlas_problems
    daemon.sample_rss()
    daemon.stop()
    leftovers = temp_files(daemon.data)
    problems += ["temp file left: " + f for f in leftovers]
    if daemon.max_rss_kb / 1024 > a.max_rss_mb:
        problems.append("RSS reached %.0f MB" % (daemon.max_rss_kb / 1024))
    states = {}
    for j in final.values():
        if j:
            states[j["state"]] = states.get(j["state"], 0) + 1
    summary = {"seconds": a.seconds, "clients": a.clients, "kills": daemon.kills,
               "operations": ledger.ops, "scenes": len(ledger.scenes), "jobs": len(ledger.jobs),
               "job_states": states, "atlases_checked": checked,
               "max_rss_mb": round(daemon.max_rss_kb / 1024, 1), "problems": problems}
    with open(os.path.join(a.out, "soak.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print(json.dumps({k: v for k, v in summary.items() if k != "problems"}))
    print("problems: %d%s" % (len(problems), "".join("\n  " + p for p in problems[:20])))
    return 1 if problems else 0


if __name__ == "__main__":
    raise SystemExit(main())
