#!/usr/bin/env bash
# `rdm bake --denoise` against more samples (docs/denoise.md): for each scene and each spp of
# SPPS, three CPU bakes at the scene's own settings otherwise: undenoised, denoised across
# blocks (`--denoise`) and denoised per tile (`--denoise-scope tile`). Per bake: the RDM bake's
# seconds and the face light's (bake_report.json), the denoise's seconds and CPU-s (its
# "denoise" object), the atlas's relative error against a REF_BAKE_SPP bake of the same scene
# and the block-border difference of both (the "all" row of `rdm diff --error`), and the
# viewer's LDR-FLIP (camera 0, 640 x 360, --aa 16, 67.02 pixels per degree) against docs/spec.md
# section 7's reference (the mean of two 256-spp `rdm render`s, seeds 1 and 2). Then, per level,
# the lowest spp denoised against undenoised, and per scene the equal-quality spp: the smallest
# denoised spp whose FLIP (atlas error) is at most the undenoised BASE_SPP bake's.
#
#   scripts/denoise_eval.sh [OUTDIR] [SCENES...]
#
# Defaults: $BUILD/denoise-eval, chess island. SPPS: "1 2 4 16"; TILE_SPPS (the per-tile
# variant's spps): SPPS; BASE_SPP: 4; REF_BAKE_SPP: 256. BUILD is $RDM_BUILD_DIR or build/; RDM,
# VIEWER and EXR_TOOL override the binaries (a frozen copy, say). A finished bake, reference
# bake or reference image is reused (a bake's wall time is kept beside it in DIR.wall).
# REF_DIR holds the path-traced references SCENE_ref_640x360.exr (default OUT); a missing one is
# rendered there with EXR_TOOL: 2 x 256 spp at 640 x 360, about 35-50 s a render on a 2-core
# AMD EPYC (1.2-1.7 minutes a scene). The REF_BAKE_SPP bakes cost about 50 s (chess, S <= 64)
# and 55 s (island, S <= 128) there.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/reference.sh"
BUILD="${RDM_BUILD_DIR:-$ROOT/build}"
[[ -d $BUILD ]] && BUILD="$(cd "$BUILD" && pwd)"
OUT="${1:-$BUILD/denoise-eval}"
shift $(($# < 1 ? $# : 1))
SCENES=("$@")
((${#SCENES[@]})) || SCENES=(chess island)
read -r -a SPPS <<< "${SPPS:-1 2 4 16}"
read -r -a TILE_SPPS <<< "${TILE_SPPS:-${SPPS[*]}}"
BASE_SPP=${BASE_SPP:-4} REF_BAKE_SPP=${REF_BAKE_SPP:-256}
RDM="${RDM:-$BUILD/cli/rdm}" VIEWER="${VIEWER:-$BUILD/viewer/rdm-viewer}"
EXR_TOOL="${EXR_TOOL:-$BUILD/eval/exr_tool}"
for bin in "$RDM" "$VIEWER"; do
  [[ -x "$bin" ]] || { echo "denoise_eval.sh: missing $bin (build it first)" >&2; exit 1; }
done
RDM="$(realpath "$RDM")" VIEWER="$(realpath "$VIEWER")" EXR_TOOL="$(realpath -m "$EXR_TOOL")"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
REF_DIR="$(mkdir -p "${REF_DIR:-$OUT}" && cd "${REF_DIR:-$OUT}" && pwd)"
cd "$OUT"
for s in "${SCENES[@]}"; do  # the references first, so that a missing tool fails early
  [[ -f "$REF_DIR/${s}_ref_640x360.exr" || -x "$EXR_TOOL" ]] ||
    { echo "denoise_eval.sh: missing $EXR_TOOL (to make $REF_DIR/${s}_ref_640x360.exr)" >&2; exit 1; }
done

bake() {  # scene-file, dir, bake arguments...
  local scene=$1 dir=$2
  shift 2
  [[ -f "$dir/bake_report.json" ]] && return
  rm -rf "$dir"
  local t0 t1
  t0=$(date +%s.%N)
  "$RDM" bake --scene "$scene" -o "$dir" --backend cpu --quiet "$@" > /dev/null
  t1=$(date +%s.%N)
  python3 -c "print(f'{$t1 - $t0:.2f}')" > "$dir.wall"
}
# RDM-bake-s face-light-s denoise-s denoise-CPU-s, from bake_report.json ("-" where absent)
report() {
  python3 - "$1/bake_report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
d = r.get("denoise")
fl = r.get("face_light", {}).get("seconds")
print(f"{r['seconds']:.2f}", f"{fl:.2f}" if fl is not None else "-",
      f"{d['seconds']:.2f}" if d else "-", f"{d['cpu_seconds']:.2f}" if d else "-")
PY
}
all_row() { "$RDM" diff "$1" "$2" --error | awk '$1 == "all" {print $3, $4, $5}'; }  # err bA bB
flip() {  # scene, atlas dir -> LDR-FLIP of its image against the path-traced reference
  "$VIEWER" --scene "$1.json" --camera 0 --atlas "$2" --width 640 --height 360 --aa 16 \
    --offscreen "$2.png" --exr "$2.exr" > /dev/null
  "$RDM" flip "$REF_DIR/$1_ref_640x360.exr" "$2.exr" --ppd 67.02 | sed -n 's/mean LDR-FLIP: //p'
}
# the smallest spp of a variant whose value (column 2: FLIP, 3: atlas error) is <= the limit
equal_spp() {  # rows file, variant, column, limit
  awk -v v="$2" -v c="$3" -v lim="$4" \
    '$1 == v && $c + 0 <= lim + 0 && (m == "" || $4 + 0 < m) {m = $4 + 0}
     END {print m == "" ? "none" : m}' "$1"
}

summary=()
for s in "${SCENES[@]}"; do
  [[ -f "$s.json" ]] || "$RDM" scene --scene "$s" -o "$s.json" > /dev/null
  reference_exr "$RDM" "$EXR_TOOL" "$s.json" 256 640 360 "$REF_DIR/${s}_ref_640x360.exr"
  ref="${s}_ref$REF_BAKE_SPP"
  bake "$s.json" "$ref" --spp "$REF_BAKE_SPP"
  echo
  echo "### $s (atlas error and border difference against a $REF_BAKE_SPP-spp bake, $(cat "$ref.wall" 2> /dev/null || echo "?") s)"
  echo
  echo "| spp | variant | RDM bake s | face light s | denoise s | denoise CPU-s | denoise / RDM bake | bake wall s | atlas error | border diff (ref) | LDR-FLIP |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
  : > "$s.rows"  # variant flip error spp, for the equal-quality spp
  for spp in "${SPPS[@]}"; do
    for v in none blocks tile; do
      [[ $v == tile && " ${TILE_SPPS[*]} " != *" $spp "* ]] && continue
      dir="${s}_spp${spp}_$v"
      args=(--spp "$spp")
      [[ $v != none ]] && args+=(--denoise --denoise-scope "$v")
      bake "$s.json" "$dir" "${args[@]}"
      read -r bake_s fl_s dn_s dn_cpu < <(report "$dir")
      read -r err border ref_border < <(all_row "$dir" "$ref")
      f=$(flip "$s" "$dir")
      share=-
      [[ $dn_s != - ]] && share=$(python3 -c "print(f'{100 * $dn_s / $bake_s:.0f} %')")
      label=$v
      [[ $v == none ]] && label=undenoised
      echo "| $spp | $label | $bake_s | $fl_s | $dn_s | $dn_cpu | $share | $(cat "$dir.wall" 2> /dev/null || echo "?")" \
        "| $err | $border ($ref_border) | $f |"
      echo "$v $f $err $spp" >> "$s.rows"
    done
  done
  lo=${SPPS[0]}
  echo
  echo "Per level, $lo spp: undenoised -> denoised across blocks (border difference of the $REF_BAKE_SPP-spp bake in brackets)"
  echo
  echo "| level | texels | atlas error | border diff |"
  echo "|---|---|---|---|"
  paste <("$RDM" diff "${s}_spp${lo}_none" "$ref" --error | tail -n +2) \
    <("$RDM" diff "${s}_spp${lo}_blocks" "$ref" --error | tail -n +2) |
    awk '{printf "| %s | %s | %s -> %s | %s -> %s (%s) |\n", $1, $2, $3, $8, $4, $9, $5}'
  base_flip=$(awk -v b="$BASE_SPP" '$1 == "none" && $4 == b {print $2}' "$s.rows")
  base_err=$(awk -v b="$BASE_SPP" '$1 == "none" && $4 == b {print $3}' "$s.rows")
  if [[ -n $base_flip ]]; then
    line="| $s | $base_flip / $base_err"
    for v in blocks tile; do
      line+=" | $(equal_spp "$s.rows" "$v" 2 "$base_flip") / $(equal_spp "$s.rows" "$v" 3 "$base_err")"
    done
    summary+=("$line |")
  fi
done
if ((${#summary[@]})); then
  echo
  echo "Equal-quality spp: the smallest denoised spp (of ${SPPS[*]}) whose LDR-FLIP / atlas error is at most the undenoised $BASE_SPP-spp bake's"
  echo
  echo "| scene | undenoised $BASE_SPP spp: FLIP / error | blocks: equal-FLIP / equal-error spp | tile: equal-FLIP / equal-error spp |"
  echo "|---|---|---|---|"
  printf '%s\n' "${summary[@]}"
fi
