#!/usr/bin/env bash
# Builds the libFuzzer targets with clang++-14 (ASan + UBSan) in build-fuzz and runs the scene
# target for SECONDS (default 60), the .vox, scene-patch and bake-request targets for half of
# it each, on scratch copies of fuzz/corpus/* (the Vulkan backend is left out: no target
# needs it). Exits non-zero when a fuzzer finds a crash; the reproducer is kept under
# build-fuzz/fuzz-artifacts/.
#   usage: scripts/run_fuzz.sh [SECONDS]
set -euo pipefail

run_seconds="${1:-60}"
if ! [[ "${run_seconds}" =~ ^[0-9]+$ ]] || [[ "${run_seconds}" -lt 1 ]]; then
  echo "usage: $0 [SECONDS]  (a positive integer, default 60)" >&2
  exit 2
fi

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${root}/build-fuzz"
jobs="${RDM_FUZZ_JOBS:-2}"

if ! command -v clang++-14 >/dev/null; then
  echo "$0: clang++-14 not found (apt-get install clang-14 libclang-rt-14-dev)" >&2
  exit 2
fi

cmake -S "${root}" -B "${build}" -G Ninja \
  -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="${LINE_TABLES_CLANG:--O2 -gline-tables-only -DNDEBUG}" \
  -DRDM_FUZZ=ON -DRDM_BUILD_TESTS=OFF -DRDM_BUILD_BENCH=OFF -DRDM_VULKAN=OFF
ninja -C "${build}" -j"${jobs}" scene_fuzzer vox_fuzzer patch_fuzzer bake_request_fuzzer

work="$(mktemp -d "${TMPDIR:-/tmp}/rdm_fuzz.XXXXXX")"
trap 'rm -rf "${work}"' EXIT
artifacts="${build}/fuzz-artifacts"
mkdir -p "${artifacts}"

# A dictionary of the format's keys and tokens helps the mutator reach deep fields.
dict="${work}/scene.dict"
for token in format rdm-scene version size palette color roughness metallic emission \
  blocks fill voxels placements at block rot sun direction irradiance angular_radius_deg \
  sky zenith horizon ground emission_scale ambient bake spp max_bounces seed \
  max_hemisphere cameras position target fov_deg null true false base_version edits estimator \
  naive prefiltered settings mode full exact fast base_job quality draft preview final; do
  printf '"%s"\n' "${token}" >>"${dict}"
  printf '"\\"%s\\""\n' "${token}" >>"${dict}"
done
for token in '{' '}' '[' ']' ':' ',' '==' 'AAAA' '0' '1' '-1' '255' '256' '1e5' '0.27' '4096'; do
  printf '"%s"\n' "${token}" >>"${dict}"
done

# runFuzzer NAME SECONDS CORPUS_DIR ARTIFACT_PREFIX [EXTRA_FLAG...]: runs one target on a
# scratch copy of fuzz/corpus/CORPUS_DIR and exits with its status when it finds a crash.
runFuzzer() {
  local name="$1" seconds="$2" corpus="${work}/$3" prefix="${artifacts}/$4"
  cp -r "${root}/fuzz/corpus/$3" "${corpus}"
  shift 4
  local status=0
  "${build}/fuzz/${name}" \
    -max_total_time="${seconds}" -max_len=65536 -timeout=30 -rss_limit_mb=4096 \
    -artifact_prefix="${prefix}" -print_final_stats=1 "$@" "${corpus}" || status=$?
  if [[ ${status} -ne 0 ]]; then
    echo "$0: ${name} failed (exit ${status}); reproducers in ${artifacts}:" >&2
    ls -l "${artifacts}" >&2 || true
    exit "${status}"
  fi
}

vox_seconds=$(( run_seconds / 2 > 10 ? run_seconds / 2 : 10 ))
runFuzzer scene_fuzzer "${run_seconds}" scene "" -dict="${dict}"
runFuzzer vox_fuzzer "${vox_seconds}" vox vox-
runFuzzer patch_fuzzer "${vox_seconds}" patch patch- -dict="${dict}"
runFuzzer bake_request_fuzzer "${vox_seconds}" bake_request bake- -dict="${dict}"
echo "$0: no crash in ${run_seconds} s (scene loader) + ${vox_seconds} s (.vox importer)" \
  "+ ${vox_seconds} s (scene patches) + ${vox_seconds} s (bake requests)"
