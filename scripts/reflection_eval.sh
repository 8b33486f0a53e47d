#!/usr/bin/env bash
# Reflections close up (issue 39, docs/results.md section 1g): for each scene, docs/spec.md section
# 7's reference (the mean of two renders at REF_SPP, seeds 1 and 2) at WIDTH x HEIGHT, one bake
# at the scene's own settings, and the viewer's LDR-FLIP (67.02 pixels per degree) with 16
# jittered frames (--aa 16) and with one (--aa 1): flat ambient, every term with the voxel walk
# off (`in-block`), and every term. With BASE_VIEWER set (an older rdm-viewer), its every-term
# image is measured too, as "before". Prints a markdown table; images and FLIP maps stay in OUT.
#
#   scripts/reflection_eval.sh [OUTDIR] [WIDTHxHEIGHT] [SCENES...]
#
# Defaults: $BUILD/reflection-eval, 640x360, chess island mirror_floor mirror_lamp
# mirror_corridor mirror_row dark_pieces. REF_SPP: 256. BUILD is $RDM_BUILD_DIR or build/. A
# finished reference is reused. The frame cost of each term: FRAME_COST=1 adds
# `rdm-viewer --compare-rdm` at 1280 x 720 (30 frames, interleaved) per scene.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/reference.sh"
BUILD="$(cd "${RDM_BUILD_DIR:-$ROOT/build}" && pwd)"
OUT="${1:-$BUILD/reflection-eval}"
SIZE="${2:-640x360}"
shift $(($# < 2 ? $# : 2))
SCENES=("$@")
((${#SCENES[@]})) || SCENES=(chess island mirror_floor mirror_lamp mirror_corridor mirror_row dark_pieces)
W=${SIZE%x*} H=${SIZE#*x} REF_SPP=${REF_SPP:-256}
RDM="$BUILD/cli/rdm" VIEWER="$BUILD/viewer/rdm-viewer" EXR_TOOL="$BUILD/eval/exr_tool"
for bin in "$RDM" "$VIEWER" "$EXR_TOOL" ${BASE_VIEWER:+"$BASE_VIEWER"}; do
  [[ -x "$bin" ]] || { echo "reflection_eval.sh: missing $bin (build it first)" >&2; exit 1; }
done
mkdir -p "$OUT"
cd "$OUT"
walk_off="rdm,diffuse,specular,sun,shadows,emission,background,face-light,block-blend,face-light-filter"
flip() { "$RDM" flip "$1" "$2" --ppd 67.02 --map "${2%.exr}_flip.png" | sed -n 's/mean LDR-FLIP: //p'; }
view() {  # viewer binary, scene, image name, extra arguments...
  local bin=$1 s=$2 name=$3
  shift 3
  "$bin" --scene "$s.json" --camera 0 --atlas "${s}_atlas" --width "$W" --height "$H" \
    --offscreen "${s}_$name.png" --exr "${s}_$name.exr" "$@" > /dev/null
  flip "${s}_ref_${SIZE}.exr" "${s}_$name.exr"
}
header="| scene ($SIZE) | aa | flat | walk off |${BASE_VIEWER:+ before |} **every term** |"
echo "$header"
echo "|---|---|---|---|${BASE_VIEWER:+---|}---|"
for s in "${SCENES[@]}"; do
  "$RDM" scene --scene "$s" -o "$s.json"  # a file, so that an older BASE_VIEWER reads it too
  reference_exr "$RDM" "$EXR_TOOL" "$s" "$REF_SPP" "$W" "$H" "${s}_ref_${SIZE}.exr"
  rm -rf "${s}_atlas"
  "$RDM" bake --scene "$s" -o "${s}_atlas" --backend cpu --quiet > /dev/null
  for aa in 16 1; do
    row="| $s | $aa | $(view "$VIEWER" "$s" "flat_aa$aa" --no-rdm --aa "$aa")"
    row+=" | $(view "$VIEWER" "$s" "walk_off_aa$aa" --terms "$walk_off" --aa "$aa")"
    [[ -n "${BASE_VIEWER:-}" ]] && row+=" | $(view "$BASE_VIEWER" "$s" "before_aa$aa" --aa "$aa")"
    echo "$row | **$(view "$VIEWER" "$s" "every_aa$aa" --aa "$aa")** |"
  done
done
if [[ "${FRAME_COST:-0}" == 1 ]]; then
  for s in "${SCENES[@]}"; do
    echo "frame cost, $s:"
    "$VIEWER" --scene "$s" --camera 0 --atlas "${s}_atlas" --width 1280 --height 720 \
      --offscreen "${s}_cost.png" --frames 30 --compare-rdm | grep '^|'
  done
fi
