#!/usr/bin/env bash
# Fresh Debian 12 machine -> every test: the Release suite, the same suite under
# AddressSanitizer + UndefinedBehaviorSanitizer, and a bounded libFuzzer run of the loader.
# FUZZ_SECONDS (default 60) bounds the fuzzing; RDM_SKIP_SANITIZE=1 skips the ASan pass.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
JOBS=$(nproc)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$JOBS"
(cd build && ctest --output-on-failure -j"$JOBS")

if [[ "${RDM_SKIP_SANITIZE:-0}" != 1 ]]; then
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRDM_SANITIZE=ON -DRDM_BUILD_BENCH=OFF
  cmake --build build-asan -j"$JOBS"
  (cd build-asan && ctest --output-on-failure -j"$JOBS")
fi

if [[ -x scripts/run_fuzz.sh ]]; then
  bash scripts/run_fuzz.sh "${FUZZ_SECONDS:-60}"
fi

# The closing line of the whole run (the Release suite's count).
(cd build && ctest -j"$JOBS" 2>&1 | tail -n 3)
