#!/usr/bin/env bash
# Peak RSS of `rdm serve` over one full job of a generated world (docs/performance.md,
# "Memory: bounded by the work in flight"). Usage: daemon_memory.sh RDMS [RDM_BINARY]
set -euo pipefail
rdms=${1:-20000}
rdm=${2:-build/cli/rdm}
work=$(mktemp -d)
trap 'kill "$pid" 2>/dev/null || true; rm -rf "$work"' EXIT
python3 "$(dirname "$0")/../../bench/gen_world.py" --rdms "$rdms" > "$work/world.json"
${RDM_WRAP:-} "$rdm" serve --data-dir "$work/data" --port 0 > "$work/serve.log" 2>&1 &
pid=$!
until grep -q "listening on" "$work/serve.log"; do sleep 0.2; done
url=$(grep -o "http://[0-9.:]*" "$work/serve.log" | head -1)
json='Content-Type: application/json'
scene=$(curl -sf -H "$json" --data-binary @"$work/world.json" "$url/v1/scenes" |
  python3 -c 'import json,sys; print(json.load(sys.stdin)["id"])')
rss_after_upload=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status")
start=$(date +%s.%N)
job=$(curl -sf -H "$json" -d '{"face_light": 0}' "$url/v1/scenes/$scene/bakes" |
  python3 -c 'import json,sys; print(json.load(sys.stdin)["id"])')
state=queued
while [ "$state" != succeeded ]; do
  state=$(curl -sf "$url/v1/jobs/$job?wait=5" |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["state"])')
  case $state in failed|cancelled) echo "job $state"; curl -s "$url/v1/jobs/$job"; exit 1 ;; esac
done
end=$(date +%s.%N)
hwm=$(awk '/VmHWM/ {print $2}' "/proc/$pid/status")
printf 'rdms %s  job %.1f s  VmRSS after upload %d MB  VmHWM %d MB  atlas %s\n' "$rdms" \
  "$(echo "$end - $start" | bc)" $((rss_after_upload / 1024)) $((hwm / 1024)) \
  "$(du -ch "$work"/data/jobs/*/out/atlas*.exr | tail -1 | cut -f1)"
