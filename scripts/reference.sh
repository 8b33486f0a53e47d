# docs/spec.md section 7's reference image, for the evaluation scripts that source this file:
# the per-pixel mean of two `rdm render`s of camera 0, seeds 1 and 2.
#
#   reference_exr RDM EXR_TOOL SCENE SPP WIDTH HEIGHT OUT.exr
#
# The renders are OUT_seed1.exr and OUT_seed2.exr; a finished OUT.exr is kept, not rendered again.
# RDM_RENDER_BACKEND (cpu, vulkan or auto, the default) picks `rdm render --backend`.
reference_exr() {
  local rdm=$1 exr_tool=$2 scene=$3 spp=$4 width=$5 height=$6 out=$7
  [[ -f $out ]] && return
  for seed in 1 2; do
    "$rdm" render --scene "$scene" --camera 0 --spp "$spp" --seed "$seed" --width "$width" \
      --height "$height" --backend "${RDM_RENDER_BACKEND:-auto}" --quiet -o "${out%.exr}_seed$seed.exr" > /dev/null
  done
  "$exr_tool" mean "$out" "${out%.exr}_seed1.exr" "${out%.exr}_seed2.exr"
}
