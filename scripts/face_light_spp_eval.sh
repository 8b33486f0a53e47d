#!/usr/bin/env bash
# The face light's spp against its cost and the viewer's error (docs/results.md section 1f):
# for each scene, the reference of docs/spec.md section 7 at 640 x 360 (the mean of two 256-spp
# renders, seeds 1 and 2), then per SPP one bake with --face-light SPP and the viewer's image
# with every term (16 jittered frames) without the face light, with it as baked, and with it
# filtered (term face-light-filter, docs/spec.md section 6); LDR-FLIP of each.
#
#   scripts/face_light_spp_eval.sh [OUTDIR] [SPPS] [SCENES...]
#
# Defaults: $BUILD/face-light-spp, "4 8 16 32", island island_night. island_night is island
# lit by its lamps alone (a dim sky, no sun), written here. BUILD is $RDM_BUILD_DIR or build/;
# RDM overrides the rdm binary that bakes (an older build, to compare estimators).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/reference.sh"
BUILD="$(cd "${RDM_BUILD_DIR:-$ROOT/build}" && pwd)"
OUT="${1:-$BUILD/face-light-spp}"
read -r -a SPPS <<< "${2:-4 8 16 32}"
shift $(($# < 2 ? $# : 2))
SCENES=("$@")
((${#SCENES[@]})) || SCENES=(island island_night)
RENDER="$BUILD/cli/rdm" BAKER="${RDM:-$BUILD/cli/rdm}" VIEWER="$BUILD/viewer/rdm-viewer"
EXR_TOOL="$BUILD/eval/exr_tool"
for bin in "$RENDER" "$BAKER" "$VIEWER" "$EXR_TOOL"; do
  [[ -x "$bin" ]] || { echo "face_light_spp_eval.sh: missing $bin (build it first)" >&2; exit 1; }
done
mkdir -p "$OUT"
cd "$OUT"
if [[ ! -f island_night.json ]]; then
  "$RENDER" scene --scene island -o island_night.json
  python3 - <<'PY'
import json
s = json.load(open("island_night.json"))
s["sky"] = {"zenith": [0.004, 0.006, 0.012], "horizon": [0.01, 0.012, 0.016],
            "ground": [0.003, 0.003, 0.003]}
s.pop("sun", None)
s["ambient"] = [0.01, 0.01, 0.012]
json.dump(s, open("island_night.json", "w"), indent=1)
PY
fi
without="rdm,diffuse,specular,sun,shadows,emission,background,in-block,block-blend"
flip() { "$RENDER" flip "$1" "$2" --ppd 67.02 | sed -n 's/mean LDR-FLIP: //p'; }
view() {  # scene, atlas, terms, image
  "$VIEWER" --scene "$1" --camera 0 --atlas "$2" --width 640 --height 360 --aa 16 --terms "$3" \
    --offscreen "${4%.exr}.png" --exr "$4" > /dev/null
}
echo "| scene | face light spp | RDM bake | face light bake (share) | FLIP without | FLIP with | FLIP filtered |"
echo "|---|---|---|---|---|---|---|"
for s in "${SCENES[@]}"; do
  arg=$s
  [[ -f $s.json ]] && arg=$s.json
  reference_exr "$RENDER" "$EXR_TOOL" "$arg" 256 640 360 "${s}_ref.exr"
  for spp in "${SPPS[@]}"; do
    atlas="${s}_fl$spp"
    rm -rf "$atlas"
    "$BAKER" bake --scene "$arg" -o "$atlas" --face-light "$spp" --backend cpu --quiet > /dev/null
    read -r rdm_s fl_s < <(python3 -c "import json; r = json.load(open('$atlas/bake_report.json')); print(r['seconds'], r['face_light']['seconds'])")
    view "$arg" "$atlas" "$without" "${atlas}_without.exr"
    view "$arg" "$atlas" "$without,face-light" "${atlas}_with.exr"
    view "$arg" "$atlas" "$without,face-light,face-light-filter" "${atlas}_filtered.exr"
    printf '| %s | %s | %.2f s | %.2f s (%.0f %%) | %s | %s | %s |\n' "$s" "$spp" "$rdm_s" "$fl_s" \
      "$(python3 -c "print(100 * $fl_s / $rdm_s)")" "$(flip "${s}_ref.exr" "${atlas}_without.exr")" \
      "$(flip "${s}_ref.exr" "${atlas}_with.exr")" "$(flip "${s}_ref.exr" "${atlas}_filtered.exr")"
  done
done
