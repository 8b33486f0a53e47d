#!/usr/bin/env python3
"""Time and peak memory of `rdm serve` for large JSON bodies (docs/deploy.md).

Usage: http_body_bench.py RDM_BINARY [MEGABYTES]
Starts a daemon per body shape on an ephemeral loopback port, posts one body of about
MEGABYTES (default 30) to POST /v1/scenes and prints the status, the wall time of the request
and the daemon's peak RSS (VmHWM) before and after, as a multiple of the body size.
"""
import http.client
import json
import os
import subprocess
import sys
import tempfile
import time


def vm_hwm_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return -1


def shapes(mb):
    n = mb << 20
    yield "empty objects [{},{},...]", ("[" + ",".join(["{}"] * (n // 3)) + "]").encode()
    yield "small numbers [0,0,...]", ("[" + ",".join(["0"] * (n // 2)) + "]").encode()
    head = '{"format":"rdm-scene","version":1,"size":[256,64,256],"palette":[{"color":[200,200,200]}],'
    head += '"blocks":{"b":{"fill":1}},"placements":['
    per = '{"at":[%d,%d,%d],"block":"b"}'
    items, size, i = [], len(head), 0
    while size < n:
        s = per % (i % 256, (i // 256) % 64, (i // 16384) % 256)
        items.append(s)
        size += len(s) + 1
        i += 1
    yield "scene with %d placements" % len(items), (head + ",".join(items) + "]}").encode()


def main():
    binary = sys.argv[1]
    mb = int(sys.argv[2]) if len(sys.argv) > 2 else 30
    for name, body in shapes(mb):
        with tempfile.TemporaryDirectory() as data:
            proc = subprocess.Popen([binary, "serve", "--data-dir", data, "--port", "0",
                                     "--max-body", str(64 << 20)], stdout=subprocess.PIPE)
            port = int(proc.stdout.readline().decode().rsplit(":", 1)[1])
            before = vm_hwm_kib(proc.pid)
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
            start = time.monotonic()
            conn.request("POST", "/v1/scenes", body, {"Content-Type": "application/json"})
            reply = conn.getresponse()
            text = reply.read()
            seconds = time.monotonic() - start
            after = vm_hwm_kib(proc.pid)
            proc.terminate()
            proc.wait()
            detail = json.loads(text).get("detail", "") if reply.status >= 400 else ""
            print(f"{name}: {len(body) / 2**20:.1f} MiB -> {reply.status} in {seconds:.2f} s, "
                  f"peak RSS {before / 1024:.0f} -> {after / 1024:.0f} MiB "
                  f"({(after - before) * 1024 / len(body):.1f}x body) {detail[:60]}")


if __name__ == "__main__":
    main()
