#!/usr/bin/env bash
# Fresh Debian 12 machine -> every test: the Release suite, the same suite under
# AddressSanitizer + UndefinedBehaviorSanitizer, the core and daemon tests under
# ThreadSanitizer, and bounded libFuzzer runs of the loaders.
# FUZZ_SECONDS (default 60) bounds the fuzzing; RDM_SKIP_SANITIZE=1 skips the ASan pass.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
JOBS=$(nproc)
run_start=$SECONDS
# One line per stage with the seconds since the start, so the 60-minute budget can be read off a log.
stage() { echo "== [$((SECONDS - run_start)) s] $*"; }
# Sanitizer builds keep -O2 but only line tables: reports still name file:line, and a clang
# ASan compile of libs/bake/src/bake.cpp takes 13 s instead of 26 s with full -g (g++ TSan:
# -g1 10 s against 13 s).
export LINE_TABLES_CLANG="-O2 -gline-tables-only -DNDEBUG"

# Formatting is part of the contract (.clang-format); shaders/shared is GLSL-compatible C.
git ls-files '*.cpp' '*.h' | grep -v '^shaders/shared/' | xargs clang-format --dry-run --Werror

stage "Release build"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$JOBS"
stage "Release tests"
release_log="$PWD/build/ctest-release.log"
(cd build && ctest --output-on-failure -j"$JOBS" | tee "$release_log")

# The Slurm path for real (docs/deploy.md "Slurm"): a one-node cluster from Debian's
# slurm-wlm and munge, a 4-shard job array and its merge for chess and island, compared byte
# for byte with one-process bakes (about 30 s, plus the packages' install).
stage "Slurm sharded bake"
SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
$SUDO bash scripts/slurm_test.sh build/cli/rdm

if [[ "${RDM_SKIP_SANITIZE:-0}" != 1 ]]; then
  # clang: g++ 12 takes 3-5x as long to compile the same files under ASan + UBSan (tests/
  # server_test.cpp 115 s against 39 s, libs/bake/src/bake.cpp 83 s against 17 s). The eval tools
  # are left out: eval_quick runs in the Release pass only.
  stage "ASan/UBSan build"
  cmake -S . -B build-asan -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$LINE_TABLES_CLANG" -DRDM_SANITIZE=ON -DRDM_BUILD_BENCH=OFF -DRDM_BUILD_EVAL=OFF
  cmake --build build-asan -j"$JOBS"
  # Mesa's Vulkan loader dlcloses its drivers, so LeakSanitizer reports their allocations
  # from an "<unknown module>" that no suppression can name. Tests whose process touches
  # Vulkan (the Vulkan and viewer tests, and the rdm processes the CLI and server tests
  # start, since `--backend auto` probes for a device) run under ASan/UBSan without leak
  # detection; every in-process test of the core keeps it.
  # The viewer's image-quality tests against path-traced references (ViewerFaceLight's FLIP and
  # patch comparisons, ViewerReflections) run the same binaries as the Cli and viewer tests do
  # here, at 3-4x the Release time (100 s and 50 s): the Release pass runs them.
  stage "ASan/UBSan tests"
  VULKAN_TOUCHING="Vulkan|Viewer|Cli|Server"
  IMAGE_QUALITY="ViewerFaceLight\.(TheFaceLightAtItsDefaultSppNeverRaisesFlip|AnEmitterLightsTheFloorOfItsOwnBlock)|ViewerReflections"
  (cd build-asan && ctest --output-on-failure -j"$JOBS" -E "$VULKAN_TOUCHING")
  (cd build-asan && ASAN_OPTIONS=detect_leaks=0 ctest --output-on-failure -j"$JOBS" -R "$VULKAN_TOUCHING" \
    -E "$IMAGE_QUALITY")
fi

# ThreadSanitizer over the core and the daemon, the daemon's Vulkan worker included
# (ServerVulkan: the daemon's threads around lavapipe's). The in-process Vulkan and viewer
# tests are left out: they add no thread of ours, and Mesa's threads are not instrumented.
# Every process a test starts, the daemons too, writes its reports under
# build-tsan/tsan-reports; any report fails the pass.
# ServerResume and ServerLoad bake for 7 minutes each under TSan; they run in the two passes
# above. RDM_SKIP_TSAN=1 skips it.
if [[ "${RDM_SKIP_TSAN:-0}" != 1 ]]; then
  stage "TSan build"
  cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRDM_TSAN=ON \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
    -DRDM_BUILD_BENCH=OFF -DRDM_BUILD_EVAL=OFF -DRDM_VULKAN=ON -DRDM_BUILD_VIEWER=OFF
  cmake --build build-tsan -j"$JOBS"
  stage "TSan tests"
  reports="$PWD/build-tsan/tsan-reports"
  rm -rf "$reports" && mkdir -p "$reports"
  (cd build-tsan && TSAN_OPTIONS="log_path=$reports/report" ctest --output-on-failure \
    -j"$JOBS" -E "^Vulkan|Viewer|deploy_manifests|ServerResume|ServerLoad")
  if compgen -G "$reports/report*" > /dev/null; then
    cat "$reports"/report* >&2
    echo "ThreadSanitizer reported the races above" >&2
    exit 1
  fi
fi

if [[ -x scripts/run_fuzz.sh ]]; then
  stage "fuzzing"
  bash scripts/run_fuzz.sh "${FUZZ_SECONDS:-60}"
fi

# The closing lines of the whole run: the Release suite's count, from its one run above (a
# second run would only add a chance of a flaky failure hidden behind `tail`).
stage "done"
tail -n 3 "$release_log"
