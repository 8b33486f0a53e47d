#!/usr/bin/env bash
# Real MagicaVoxel models end to end at `--quality draft` (docs/performance.md, "Real models"):
# import with the content defaults, bake (peak RSS, seconds, CPU seconds), atlas pages and
# bytes, then the viewer at 640 x 360 (peak RSS, ms per frame).
# Usage: vox_models.sh BUILD_DIR MODEL.vox...   (prints one Markdown row per model)
set -euo pipefail
build=$1; shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| model | RDMs | bake s | CPU s per RDM | bake peak RSS | atlas pages | atlas bytes | viewer peak RSS | ms / frame |"
echo "|---|---|---|---|---|---|---|---|---|"
for vox in "$@"; do
  name=$(basename "$vox" .vox)
  "$build/cli/rdm" import "$vox" -o "$work/$name.json" > /dev/null
  /usr/bin/time -f "%e %U %S %M" -o "$work/bake.time" \
    "$build/cli/rdm" bake "$work/$name.json" -o "$work/$name" --quality draft > /dev/null 2>&1
  read -r wall user sys rss < "$work/bake.time"
  rdms=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["rdms"]))' \
    "$work/$name/index.json")
  pages=$(ls "$work/$name"/atlas*.exr | wc -l)
  bytes=$(du -cb "$work/$name"/atlas*.exr | tail -1 | cut -f1)
  /usr/bin/time -f "%M" -o "$work/view.time" "$build/viewer/rdm-viewer" --scene "$work/$name.json" \
    --atlas "$work/$name" --width 640 --height 360 --offscreen "$work/$name.png" --frames 20 \
    > "$work/view.log" 2>&1
  ms=$(grep -oE "mean frame time: [0-9.]+" "$work/view.log" | grep -oE "[0-9.]+$" | head -1)
  printf '| %s | %s | %.1f | %.4f | %d MB | %s | %d kB | %d MB | %.1f |\n' "$name" "$rdms" "$wall" \
    "$(echo "($user + $sys) / $rdms" | bc -l)" $((rss / 1024)) "$pages" $((bytes / 1000)) \
    $(($(cat "$work/view.time") / 1024)) "${ms:-0}"
done
