#!/usr/bin/env bash
# Quality with every term (docs/spec.md section 7, docs/results.md section 1e): for each
# scene, section 7's reference (the mean of two renders at REF_SPP, seeds 1 and 2), one bake
# with the scene's face light, and the viewer's images as a window shows a still view (16
# jittered frames, --aa 16): flat ambient, the thesis's terms (RDM diffuse and specular, sun,
# emission, sky), and every term (the default: + face light + in-block reflections), plus every
# term in one frame. Prints a markdown table of LDR-FLIP and reductions against the flat image,
# and writes FLIP maps and quarter-size thumbnails into OUT/results/.
#
#   scripts/quality_eval.sh [OUTDIR] [REF_SPP] [SCENE:FACE_LIGHT_SPP...]
#
# Defaults: $BUILD/quality-eval, 256, chess:64 island:8 mirror_floor:64 (the face light
# samples of scripts/bake_demo.sh). BUILD is $RDM_BUILD_DIR or build/. The references take
# 1-3 min per scene on 2 cores at 256 spp; a finished reference is reused.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/reference.sh"
BUILD="$(cd "${RDM_BUILD_DIR:-$ROOT/build}" && pwd)"
OUT="${1:-$BUILD/quality-eval}"
REF_SPP="${2:-256}"
shift $(($# < 2 ? $# : 2))
SCENES=("$@")
((${#SCENES[@]})) || SCENES=(chess:64 island:8 mirror_floor:64)
RDM="$BUILD/cli/rdm" VIEWER="$BUILD/viewer/rdm-viewer" EXR_TOOL="$BUILD/eval/exr_tool"
for bin in "$RDM" "$VIEWER" "$EXR_TOOL"; do
  [[ -x "$bin" ]] || { echo "quality_eval.sh: missing $bin (build it first)" >&2; exit 1; }
done
mkdir -p "$OUT/results"
cd "$OUT"
thesis="rdm,diffuse,specular,sun,shadows,emission,background"
flip() { "$RDM" flip "$1" "$2" --ppd 67.02 --map "$3" | sed -n 's/mean LDR-FLIP: //p'; }
reduction() { python3 -c "print('%.1f %%' % (100 * (1 - $1 / $2)))"; }
view() {  # scene, name, extra viewer arguments...
  local s=$1 name=$2
  shift 2
  "$VIEWER" --scene "$s" --camera 0 --atlas "${s}_atlas" --width 1280 --height 720 \
    --offscreen "${s}_$name.png" --exr "${s}_$name.exr" "$@" > /dev/null
}
echo "| scene | RDM bake | face light bake | flat | thesis's terms | **every term** | every term, one frame |"
echo "|---|---|---|---|---|---|---|"
for entry in "${SCENES[@]}"; do
  s=${entry%%:*} fl=${entry#*:}
  reference_exr "$RDM" "$EXR_TOOL" "$s" "$REF_SPP" 1280 720 "${s}_ref.exr"
  rm -rf "${s}_atlas"
  "$RDM" bake --scene "$s" -o "${s}_atlas" --face-light "$fl" --backend cpu --quiet > /dev/null
  read -r rdm_s fl_s < <(python3 -c "import json; r = json.load(open('${s}_atlas/bake_report.json')); print(r['seconds'], r['face_light']['seconds'])")
  view "$s" flat --no-rdm --aa 16
  view "$s" thesis --terms "$thesis" --aa 16
  view "$s" every --aa 16
  view "$s" every_1frame
  flat=$(flip "${s}_ref.exr" "${s}_flat.exr" "results/flip_${s}_flat.png")
  share=$(python3 -c "print('%.0f %%' % (100 * $fl_s / $rdm_s))")
  row="| $s | $(printf %.2f "$rdm_s") s | $(printf %.2f "$fl_s") s ($fl spp, $share) | $flat |"
  for name in thesis every every_1frame; do
    f=$(flip "${s}_ref.exr" "${s}_$name.exr" "results/flip_${s}_$name.png")
    row+=" $f ($(reduction "$f" "$flat")) |"
  done
  echo "$row"
  for name in ref flat thesis every; do
    "$EXR_TOOL" thumb "${s}_$name.exr" "results/${s}_$name.png" --scale 4
  done
done
