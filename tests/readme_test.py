#!/usr/bin/env python3
"""Walks the README's commands as a new user would: every `rdm` and `rdm-viewer` line of its
code blocks runs, in order, in a scratch directory, and must exit 0; every option a line
names must be in that verb's --help. The only changes to a line are the substitutions in
SUBSTITUTIONS (a free port, files a user would have, a lighter render); the lines that are
not run say why in SKIPPED.

usage: readme_test.py REPO BUILD_DIR
"""
import json
import os
import re
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time

# Lines not run, by a fragment of the line, and why.
SKIPPED = {
    "rdm-viewer --scene chess --atlas out/chess  ": "opens a window until closed (ViewerWindow, ViewerInput)",
    "--server http://127.0.0.1:8080    #": "opens a window until closed (ViewerLive)",
    "--face-light 16": "opens a window until closed (ViewerLive)",
    "--device llvmpipe": "opens a window until closed (ViewerDevice)",
    "rdm serve --data-dir": "the test starts this daemon itself, with a free port",
    "scripts/": "an evaluation run of its own (docs/performance.md, docs/deploy.md)",
}

# Applied to every line in this order: (pattern, replacement, why).
def substitutions(port, build):
    return [
        (r"^\./build/", build + "/", "the build directory of this test run"),
        (r"^rdm ", build + "/cli/rdm ", "rdm on the PATH"),
        (r"(?<=; )rdm ", build + "/cli/rdm ", "rdm on the PATH"),
        (r"8080", str(port), "a free port"),
        (r"\bURL\b", "http://127.0.0.1:%d" % port, "the daemon started by the test"),
        (r"--spp 256", "--spp 4", "the reference render at 4 spp: its options, not its noise"),
        (r" \.\.\. ", " ", "the shards baked by the setup"),
    ]


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def readme_lines(readme):
    """Commands of the README's code blocks: continuation lines joined, comments dropped."""
    out, block, pending = [], False, ""
    for raw in open(readme, encoding="utf-8"):
        line = raw.rstrip("\n")
        if line.startswith("```"):
            block = not block
            continue
        if not block:
            continue
        if pending:
            line = pending + " " + line.strip()
            pending = ""
        if line.endswith("\\"):
            pending = line[:-1].rstrip()
            continue
        out.append(line)
    return out


def command_part(line):
    """The line without its comment and optional [..] groups; continuation-only lines are ''."""
    if line.lstrip().startswith("#") or line.startswith(" "):
        return ""
    code = re.split(r"\s+#\s", line, maxsplit=1)[0]
    code = re.sub(r"\s*\[[^\]]*\]", "", code)
    return re.sub(r"\s*\[.*$", "", code).strip()


def is_ours(code):
    return bool(re.match(r"^(\./build/(cli/rdm|viewer/rdm-viewer)|rdm) ", code))


def alternatives(code):
    """`rdm scene --list | --scene chess -o x.json | SCENE.json`: three commands of one verb."""
    if " | " not in code:
        return [code]
    parts = code.split(" | ")
    head = " ".join(parts[0].split()[:2])
    return [parts[0]] + [head + " " + p for p in parts[1:]]


def options_of(line):
    return set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", line.split(" # ")[0]))


class Walk:
    def __init__(self, repo, build, work):
        self.repo, self.build, self.work = repo, build, work
        self.rdm = os.path.join(build, "cli", "rdm")
        self.viewer = os.path.join(build, "viewer", "rdm-viewer")
        self.port = free_port()
        self.ids = {}
        self.failures = []

    def run(self, cmd, check=True):
        r = subprocess.run(["bash", "-c", cmd], cwd=self.work, capture_output=True, text=True,
                           timeout=600)
        if check and r.returncode != 0:
            self.failures.append("%s\n  exit %d: %s" % (cmd, r.returncode, r.stderr.strip()[-600:]))
        return r

    def setup(self):
        """What a user following the README has before its lines: a daemon, a .vox model,
        shards to merge, the demo's out/chess and a second atlas to diff against."""
        os.makedirs(os.path.join(self.work, "out"))
        self.daemon = subprocess.Popen(
            [self.rdm, "serve", "--data-dir", os.path.join(self.work, "rdm-data"), "--port",
             str(self.port), "--log-level", "warn"], cwd=self.work)
        write_vox(os.path.join(self.work, "model.vox"))
        for i in range(2):
            self.run("%s bake --scene chess --shard %d/2 -q -o out/shard-%d" % (self.rdm, i, i))
        self.run("%s bake --scene chess -q -o out/chess && mkdir other && cp -r out/chess other/"
                 % self.rdm)
        self.run("%s render --scene island --camera 0 --spp 1 -o test.exr" % self.rdm)
        deadline = time.time() + 30
        while self.run("curl -sf http://127.0.0.1:%d/healthz" % self.port, False).returncode:
            if time.time() > deadline:
                self.failures.append("the daemon did not answer /healthz within 30 s")
                return
            time.sleep(0.2)

    def before(self, code):
        """Files a line reads that an earlier line of the README makes in the user's head."""
        if "edited.json" in code and not os.path.exists(os.path.join(self.work, "edited.json")):
            scene = json.load(open(os.path.join(self.work, "chess.json")))
            scene["sun"]["irradiance"] = [2 * c for c in scene["sun"]["irradiance"]]
            json.dump(scene, open(os.path.join(self.work, "edited.json"), "w"))
        for key in ("SCENE_ID", "JOB"):
            if key in code and key not in self.ids:
                self.failures.append("no %s from an earlier line for: %s" % (key, code))
        for key, value in self.ids.items():
            code = re.sub(r"\b%s\b" % key, value, code)
        return code.replace("SCENE.json", "chess.json")

    def after(self, result):
        for key, word in (("SCENE_ID", "scene"), ("JOB", "job")):
            m = re.search(r"^%s (\S+)$" % word, result.stdout, re.M)
            if m:
                self.ids[key] = m.group(1)

    def line(self, raw):
        code = command_part(raw)
        if not code or not is_ours(code):
            return
        why = next((w for frag, w in SKIPPED.items() if frag in raw), None)
        if why:
            print("skipped (%s): %s" % (why, code))
            return
        if "rdm-viewer" in code and not os.path.exists(self.viewer):
            print("skipped (this build has no viewer, RDM_BUILD_VIEWER=OFF): %s" % code)
            return
        for pattern, replacement, _ in substitutions(self.port, self.build):
            code = re.sub(pattern, replacement, code)
        self.check_options(raw, code)
        for alt in alternatives(code):
            for cmd in alt.split(" ; "):
                cmd = self.before(cmd)
                print("run:", cmd)
                self.after(self.run(cmd))

    def check_options(self, raw, code):
        words = code.split()
        binary = words[0]
        verb = words[1] if "rdm-viewer" not in binary and len(words) > 1 else ""
        helptext = self.run("%s %s --help" % (binary, verb), False).stdout
        for opt in options_of(raw) - {"--help"}:
            if opt not in helptext:
                self.failures.append("%s: the README names %s, which `%s --help` lacks" %
                                     (raw.strip(), opt, (os.path.basename(binary) + " " + verb).strip()))


def write_vox(path):
    """A 4x4x2 MagicaVoxel model: a floor of colour 1 and one voxel of colour 2."""
    voxels = [(x, y, 0, 1) for x in range(4) for y in range(4)] + [(1, 1, 1, 2)]
    size = struct.pack("<3i", 4, 4, 2)
    xyzi = struct.pack("<i", len(voxels)) + b"".join(struct.pack("<4B", *v) for v in voxels)
    rgba = b"".join(struct.pack("<4B", 200, 200, 200, 255) for _ in range(256))
    chunks = b""
    for name, body in ((b"SIZE", size), (b"XYZI", xyzi), (b"RGBA", rgba)):
        chunks += name + struct.pack("<2i", len(body), 0) + body
    with open(path, "wb") as f:
        f.write(b"VOX " + struct.pack("<i", 150) + b"MAIN" + struct.pack("<2i", 0, len(chunks)))
        f.write(chunks)


def main():
    repo, build = sys.argv[1], os.path.abspath(sys.argv[2])
    work = tempfile.mkdtemp(prefix="rdm_readme_")
    walk = Walk(repo, build, work)
    try:
        walk.setup()
        for raw in readme_lines(os.path.join(repo, "README.md")):
            walk.line(raw)
    finally:
        if getattr(walk, "daemon", None):
            walk.daemon.terminate()
            walk.daemon.wait(timeout=30)
        shutil.rmtree(work, ignore_errors=True)
    for f in walk.failures:
        print("FAILED:", f, file=sys.stderr)
    return 1 if walk.failures else 0


if __name__ == "__main__":
    sys.exit(main())
