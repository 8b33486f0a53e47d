#!/usr/bin/env bash
# Evaluation harness (docs/spec.md section 7): FLIP against path-traced references,
# accuracy against bake time, incremental rebakes, effect specialisation and frame cost.
#
#   scripts/eval.sh [--quick|--full] [OUTDIR]
#
#   --quick  tiny settings (160 x 90, a few samples, 2-3 sweep points); runs in about
#            10 s on 2 cores and is the ctest test `eval_quick`. Default.
#   --full   docs/spec.md section 7's settings (1280 x 720); took 13 minutes on 2 shared cores; it
#            writes docs/results.md and docs/results/ (plots, error maps, thumbnails),
#            keeping the sections of docs/results.md it does not produce (1b-1e, 2b, 5).
#   OUTDIR   working directory for images, atlases and logs
#            (default: $RDM_BUILD_DIR/eval-quick or eval-full).
#
# Environment: RDM_BUILD_DIR, the CMake build directory holding cli/rdm, viewer/rdm-viewer,
# bench/rdm_bench and eval/* (default: build/ under the repository root). RDM_EVAL_DOCS (full
# mode only): where results.md and results/ go (default: docs/ of the repository).
# RDM_RENDER_BACKEND: `rdm render --backend` for the references (cpu, vulkan, or auto, the
# default: a Vulkan GPU when there is one, else the CPU).
#
# Exit status: 0 when every step ran, every reported number is present and finite, and the
# quality floors hold (run_eval.py: FLIP reduction against flat, error falling with spp, the
# exact incremental atlas equal to the full one); 1 otherwise (the failing step and command are printed); 2 for a bad command line.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
MODE=quick
OUTDIR=""
for arg in "$@"; do
  case "$arg" in
    --quick) MODE=quick ;;
    --full) MODE=full ;;
    -h|--help) sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "eval.sh: unknown option '$arg'" >&2; exit 2 ;;
    *) [[ -z "$OUTDIR" ]] || { echo "eval.sh: more than one OUTDIR" >&2; exit 2; }; OUTDIR="$arg" ;;
  esac
done
BUILD="${RDM_BUILD_DIR:-$ROOT/build}"
BUILD="$(cd "$BUILD" 2>/dev/null && pwd)" || { echo "eval.sh: build directory '${RDM_BUILD_DIR:-$ROOT/build}' does not exist (set RDM_BUILD_DIR)" >&2; exit 1; }
OUTDIR="${OUTDIR:-$BUILD/eval-$MODE}"
DOCS="${RDM_EVAL_DOCS:-$ROOT/docs}"

missing=0
for bin in cli/rdm viewer/rdm-viewer bench/rdm_bench eval/atlas_rmse eval/exr_tool eval/effect_bench; do
  if [[ ! -x "$BUILD/$bin" ]]; then
    echo "eval.sh: missing $BUILD/$bin (build it: ninja -C $BUILD)" >&2
    missing=1
  fi
done
for tool in python3; do
  command -v "$tool" >/dev/null || { echo "eval.sh: '$tool' is not installed (scripts/install_deps.sh)" >&2; missing=1; }
done
((missing == 0)) || exit 1

mkdir -p "$OUTDIR"
start=$(date +%s)
echo "eval.sh: mode $MODE, build $BUILD, output $OUTDIR"
status=0
python3 "$ROOT/scripts/eval/run_eval.py" --mode "$MODE" --build "$BUILD" --out "$OUTDIR" \
  --root "$ROOT" --docs "$DOCS" || status=$?
echo "eval.sh: mode $MODE finished in $(( $(date +%s) - start )) s with status $status"
exit "$status"
