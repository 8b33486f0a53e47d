#!/usr/bin/env bash
# The Vulkan bake beside the CPU bake (docs/vulkan.md, "CPU and Vulkan at the scenes' defaults"):
# chess, island and terrain at their own settings (prefiltered estimator), each backend with
# seeds 1 and 2, the face light off (it bakes on the CPU for both). Per bake: wall seconds and
# process CPU-seconds (/usr/bin/time; lavapipe's threads included), rays; per pair: the
# seed-to-seed RMSE of each backend (the noise) and, at the same seed, the backends' RMSE and
# mean difference (test minus reference, relative). Prints a Markdown table.
# Usage: scripts/bench/vulkan_vs_cpu.sh [BUILD_DIR] [SCENES...]   (default: build chess island terrain)
set -euo pipefail
build=${1:-build}
shift || true
scenes=("$@")
[[ ${#scenes[@]} -eq 0 ]] && scenes=(chess island terrain)
rdm="$build/cli/rdm" rmse="$build/eval/atlas_rmse"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

bake() {  # scene backend seed -> "wall cpu rays"
  local dir="$out/$1-$2-$3"
  /usr/bin/time -f "%e %U %S" -o "$dir.time" \
    "$rdm" bake --scene "$1" --backend "$2" --seed "$3" --face-light 0 -q -o "$dir" > /dev/null
  python3 - "$dir.time" "$dir/bake_report.json" <<'PY'
import json, sys
wall, user, sys_ = map(float, open(sys.argv[1]).read().split()[-3:])
print(wall, user + sys_, json.load(open(sys.argv[2]))["rays"])
PY
}
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$@"; }

echo "| scene | backend | seconds | CPU-seconds | rays | M rays per CPU-second | seed-to-seed RMSE |"
echo "|---|---|---|---|---|---|---|"
for scene in "${scenes[@]}"; do
  for backend in cpu vulkan; do
    read -r wall cpu rays < <(bake "$scene" "$backend" 1)
    bake "$scene" "$backend" 2 > /dev/null
    "$rmse" "$out/$scene-$backend-1" "$out/$scene-$backend-2" --json "$out/$scene-$backend.json" > /dev/null
    printf "| %s | %s | %.2f | %.2f | %s | %.2f | %.3g |\n" "$scene" "$backend" "$wall" "$cpu" \
      "$rays" "$(python3 -c "print($rays / $cpu / 1e6)")" "$(field "$out/$scene-$backend.json" rmse)"
  done
  "$rmse" "$out/$scene-cpu-1" "$out/$scene-vulkan-1" --json "$out/$scene-x.json" > /dev/null
  printf "| %s | Vulkan vs CPU, seed 1 | | | | | RMSE %.3g, mean difference %.2g (relative) |\n" \
    "$scene" "$(field "$out/$scene-x.json" rmse)" "$(field "$out/$scene-x.json" relative_mean_difference)"
done
