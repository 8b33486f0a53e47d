#!/usr/bin/env bash
# Fresh Debian 12 machine -> the RDM atlas of the built-in default scene (chess) in out/chess.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target rdm
# --face-light: the diffuse light of every voxel face as well (docs/spec.md section 3.2).
./build/cli/rdm bake --scene "${1:-chess}" -o "out/${1:-chess}" --face-light 64
