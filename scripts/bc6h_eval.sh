#!/usr/bin/env bash
# The bc6h atlas in the viewer (issue 43, docs/bc6h.md "Viewer image" and "The viewer's
# texture"): for each scene, a float32 and a bc6h bake at the scene's defaults, the file bytes,
# the viewer's LDR- and HDR-FLIP of the bc6h atlas against the float32 one (640 x 360, camera 0,
# decoded to RGBA16F), the stored BC6H texture against the decoded one, the device bytes of
# each, and the frame time of each (1280 x 720, 30 frames, ROUNDS rounds, the modes alternating).
#
#   scripts/bc6h_eval.sh [OUTDIR] [SCENES...]
#
# Defaults: $BUILD/bc6h-eval, chess island terrain; ROUNDS 2. BUILD is $RDM_BUILD_DIR or
# build/. A finished bake is reused.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$(cd "${RDM_BUILD_DIR:-$ROOT/build}" && pwd)"
OUT="${1:-$BUILD/bc6h-eval}"
shift $(($# < 1 ? $# : 1))
SCENES=("$@")
((${#SCENES[@]})) || SCENES=(chess island terrain)
ROUNDS=${ROUNDS:-2}
RDM="$BUILD/cli/rdm" VIEWER="$BUILD/viewer/rdm-viewer"
for bin in "$RDM" "$VIEWER"; do
  [[ -x "$bin" ]] || { echo "bc6h_eval.sh: missing $bin (build it first)" >&2; exit 1; }
done
mkdir -p "$OUT"
cd "$OUT"
flip() { "$RDM" flip "$1" "$2" --hdr | awk '{print $NF}' | paste -sd/ | sed 's#/# / #'; }  # LDR / HDR
view() {  # scene atlas-dir output-stem mode
  "$VIEWER" --scene "$1" --atlas "$2" --width 640 --height 360 --offscreen "$3.png" --exr "$3.exr" \
    --bc6h-texture "$4" > "$3.log" 2>&1
  sed -n 's/^atlas texture: \(.*\) on the device$/\1/p' "$3.log"
}
frame_ms() {  # scene atlas-dir mode
  "$VIEWER" --scene "$1" --atlas "$2" --width 1280 --height 720 --offscreen frame.png --frames 30 \
    --bc6h-texture "$3" 2>&1 | sed -n 's/^mean frame time: \([0-9.]*\) ms.*/\1/p'
}
echo "| scene | float32 atlas.exr | atlas.ktx2 + depth.exr | bc6h vs float32 LDR / HDR-FLIP | stored vs decoded LDR / HDR-FLIP | device: decoded / stored | frame ms decoded | frame ms stored |"
echo "|---|---|---|---|---|---|---|---|"
for s in "${SCENES[@]}"; do
  for f in float32 bc6h; do
    [[ -f "$s-$f/index.json" ]] || "$RDM" bake --scene "$s" -o "$s-$f" --radiance "$f" -q > /dev/null
  done
  view "$s" "$s-float32" "$s-float32" decoded > /dev/null
  decoded=$(view "$s" "$s-bc6h" "$s-decoded" decoded)
  stored=$(view "$s" "$s-bc6h" "$s-stored" stored)
  f32=$(stat -c %s "$s-float32/atlas.exr")
  bc=$(($(stat -c %s "$s-bc6h/atlas.ktx2") + $(stat -c %s "$s-bc6h/depth.exr")))
  ms_decoded="" ms_stored=""
  for ((r = 0; r < ROUNDS; ++r)); do
    ms_decoded+="${ms_decoded:+, }$(frame_ms "$s" "$s-bc6h" decoded)"
    ms_stored+="${ms_stored:+, }$(frame_ms "$s" "$s-bc6h" stored)"
  done
  echo "| $s | $f32 | $bc | $(flip "$s-float32.exr" "$s-decoded.exr")" \
    "| $(flip "$s-decoded.exr" "$s-stored.exr")" \
    "| $decoded / $stored | $ms_decoded | $ms_stored |"
done
