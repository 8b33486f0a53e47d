#!/usr/bin/env bash
# Face light beside the RDM diffuse (docs/results.md section 1c): for each scene, a path-traced
# reference, one bake with --face-light SPP, and the viewer's images with the RDM diffuse, with
# in-block reflections, with the face light, and with both; LDR-FLIP of each against the
# reference and the reduction against the flat-ambient image (docs/spec.md section 7's FLIP
# settings, camera 0, 1280 x 720).
#
#   scripts/face_light_eval.sh [OUTDIR] [SPP] [REF_SPP] [SCENES...]
#
# Defaults: $BUILD/face-light-eval, 64, 256, chess island mirror_floor. BUILD is
# $RDM_BUILD_DIR or build/. The references take about 1 min each on 2 cores at 256 spp.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${RDM_BUILD_DIR:-$ROOT/build}"
OUT="${1:-$BUILD/face-light-eval}"
SPP="${2:-64}"
REF_SPP="${3:-256}"
shift $(( $# < 3 ? $# : 3 ))
SCENES=("$@")
((${#SCENES[@]})) || SCENES=(chess island mirror_floor)
RDM="$BUILD/cli/rdm" VIEWER="$BUILD/viewer/rdm-viewer"
for bin in "$RDM" "$VIEWER"; do
  [[ -x "$bin" ]] || { echo "face_light_eval.sh: missing $bin (build it first)" >&2; exit 1; }
done
mkdir -p "$OUT"
cd "$OUT"
base="rdm,diffuse,specular,sun,shadows,emission,background"
declare -A TERMS=([rdm]="$base" [in-block]="$base,in-block" [face-light]="$base,face-light"
                  [both]="$base,face-light,in-block")
flip() { "$RDM" flip "$1" "$2" --ppd 67.02 --map "$3" | sed -n 's/mean LDR-FLIP: //p'; }
echo "| scene | RDM bake | face light bake | flat | RDM diffuse | + in-block | face light | face light + in-block |"
echo "|---|---|---|---|---|---|---|---|"
for s in "${SCENES[@]}"; do
  [[ -f ${s}_ref.exr ]] || "$RDM" render --scene "$s" --camera 0 --spp "$REF_SPP" --width 1280 \
    --height 720 --quiet -o "${s}_ref.exr" > /dev/null
  rm -rf "${s}_atlas"
  "$RDM" bake --scene "$s" -o "${s}_atlas" --face-light "$SPP" --backend cpu --quiet > /dev/null
  read -r rdm_s fl_s < <(python3 -c "import json; r = json.load(open('${s}_atlas/bake_report.json')); print(r['seconds'], r['face_light']['seconds'])")
  "$VIEWER" --scene "$s" --camera 0 --atlas "${s}_atlas" --no-rdm --offscreen "${s}_flat.png" \
    --exr "${s}_flat.exr" > /dev/null
  flat=$(flip "${s}_ref.exr" "${s}_flat.exr" "flip_${s}_flat.png")
  row="| $s | $(printf %.2f "$rdm_s") s | $(printf %.2f "$fl_s") s ($SPP spp) | $flat |"
  for t in rdm in-block face-light both; do
    "$VIEWER" --scene "$s" --camera 0 --atlas "${s}_atlas" --terms "${TERMS[$t]}" \
      --offscreen "${s}_$t.png" --exr "${s}_$t.exr" > /dev/null
    f=$(flip "${s}_ref.exr" "${s}_$t.exr" "flip_${s}_$t.png")
    row+=" $f ($(python3 -c "print('%.1f %%' % (100 * (1 - $f / $flat)))")) |"
  done
  echo "$row"
done
