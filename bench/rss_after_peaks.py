#!/usr/bin/env python3
"""Memory `rdm serve` keeps after large request bodies (docs/deploy.md, "Memory after peaks").

Usage: rss_after_peaks.py RDM_BINARY [BODIES] [MEGABYTES]
Starts a daemon on an ephemeral loopback port, posts BODIES (default 8) bodies of about
MEGABYTES (default 30) of `[0,0,...]` to POST /v1/scenes one at a time (each refused with
413 after it was read and parsed), waits a second and prints VmRSS before and after and the
peak (VmHWM), in MB.
"""
import http.client
import re
import subprocess
import sys
import tempfile
import time


def status_mb(pid, field):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) // 1024
    return -1


def main():
    rdm = sys.argv[1]
    bodies = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    mb = int(sys.argv[3]) if len(sys.argv) > 3 else 30
    data = tempfile.mkdtemp()
    daemon = subprocess.Popen([rdm, "serve", "--data-dir", data, "--port", "0", "--log-level",
                               "warn"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    port = int(re.search(rb":(\d+)", daemon.stdout.readline()).group(1))
    body = ("[" + ",".join(["0"] * ((mb << 20) // 2)) + "]").encode()
    before = status_mb(daemon.pid, "VmRSS")
    status = 0
    for _ in range(bodies):
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
        conn.request("POST", "/v1/scenes", body=body, headers={"Content-Type": "application/json"})
        response = conn.getresponse()
        response.read()
        status = response.status
        conn.close()
    time.sleep(1)
    print(f"{bodies} bodies of {len(body) >> 20} MB (last status {status}): VmRSS before "
          f"{before} MB, after {status_mb(daemon.pid, 'VmRSS')} MB, peak VmHWM "
          f"{status_mb(daemon.pid, 'VmHWM')} MB")
    daemon.terminate()
    daemon.wait()


if __name__ == "__main__":
    main()
