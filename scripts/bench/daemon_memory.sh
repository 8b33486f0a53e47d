#!/usr/bin/env bash
# Peak RSS of `rdm serve` over one full job of a generated world (docs/performance.md,
# "Memory: bounded by the work in flight"). Usage: daemon_memory.sh RDMS [RDM_BINARY]
# GEN_ARGS: more bench/gen_world.py flags (--max-hemisphere 64); SCENE: a scene file instead;
# JOB: the job request's JSON body; RDM_WRAP: a wrapper (heaptrack).
set -euo pipefail
rdms=${1:-20000}
rdm=${2:-build/cli/rdm}
work=$(mktemp -d)
trap 'kill "$pid" 2>/dev/null || true; rm -rf "$work"' EXIT
if [ -n "${SCENE:-}" ]; then cp "$SCENE" "$work/world.json"; else
  python3 "$(dirname "$0")/../../bench/gen_world.py" --rdms "$rdms" ${GEN_ARGS:-} > "$work/world.json"
fi
${RDM_WRAP:-} "$rdm" serve --data-dir "$work/data" --port 0 > "$work/serve.log" 2>&1 &
pid=$!
until grep -q "listening on" "$work/serve.log"; do sleep 0.2; done
url=$(grep -o "http://[0-9.:]*" "$work/serve.log" | head -1)
json='Content-Type: application/json'
default_job='{"face_light": 0}'
scene=$(curl -sf -H "$json" --data-binary @"$work/world.json" "$url/v1/scenes" |
  python3 -c 'import json,sys; print(json.load(sys.stdin)["id"])')
rss_after_upload=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status")
start=$(date +%s.%N)
posted=$(curl -sf -H "$json" -d "${JOB:-$default_job}" "$url/v1/scenes/$scene/bakes")
job=$(echo "$posted" | python3 -c 'import json,sys; print(json.load(sys.stdin)["id"])')
estimate=$(echo "$posted" |
  python3 -c 'import json,sys; print(json.load(sys.stdin)["estimate"]["memory_bytes"] >> 20)')
state=queued
while [ "$state" != succeeded ]; do
  state=$(curl -sf "$url/v1/jobs/$job?wait=5" |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["state"])')
  case $state in failed|cancelled) echo "job $state"; curl -s "$url/v1/jobs/$job"; exit 1 ;; esac
done
end=$(date +%s.%N)
hwm=$(awk '/VmHWM/ {print $2}' "/proc/$pid/status")
sleep 1
rss_after=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status")
printf 'rdms %s  job %.1f s  VmRSS after upload %d MB  VmHWM %d MB  VmRSS after %d MB  estimate %d MB  atlas %s\n' \
  "$rdms" "$(echo "$end - $start" | bc)" $((rss_after_upload / 1024)) $((hwm / 1024)) \
  $((rss_after / 1024)) "$estimate" \
  "$(du -ch "$work"/data/jobs/*/out/atlas*.exr | tail -1 | cut -f1)"
