#!/usr/bin/env bash
# The live loop measured as a user feels it (docs/performance.md, "Live rebakes"): a real
# `rdm serve` and the viewer's scripted edit (`rdm-viewer --server --offscreen --edit`) on
# the same machine, one-block edits (remove, add, paint) on chess and island at their own
# settings, each beside `rdm bake` of the same scene and a full bake in the daemon, all in
# this one run. Prints a markdown table and writes OUT/live_bench.json.
#   bash scripts/live_bench.sh [OUT_DIR] [REPEATS] [WxH of the viewer's frame, default 1280x720]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${RDM_BUILD_DIR:-build}
OUT=${1:-/tmp/rdm-live-bench}
REPEATS=${2:-3}
SIZE=${3:-1280x720}
RDM=$BUILD/cli/rdm
VIEWER=$BUILD/viewer/rdm-viewer
[[ -x $RDM && -x $VIEWER ]] || { echo "build $RDM and $VIEWER first" >&2; exit 1; }
rm -rf "$OUT" && mkdir -p "$OUT"
PORT=$((20000 + RANDOM % 20000))
"$RDM" serve --data-dir "$OUT/data" --port 0 > "$OUT/serve.log" 2>&1 &
SERVER=$!
trap 'kill $SERVER 2>/dev/null; wait $SERVER 2>/dev/null || true' EXIT
for _ in $(seq 100); do grep -q listening "$OUT/serve.log" && break; sleep 0.05; done
URL=$(grep -o 'http://[0-9.:]*' "$OUT/serve.log" | head -1)
echo "daemon at $URL (log $OUT/serve.log)" >&2
python3 scripts/bench/live_bench.py --rdm "$RDM" --viewer "$VIEWER" --url "$URL" --out "$OUT" \
  --repeats "$REPEATS" --size "$SIZE"
