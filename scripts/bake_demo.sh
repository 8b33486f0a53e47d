#!/usr/bin/env bash
# Fresh Debian 12 machine -> the RDM atlas of the built-in default scene (chess) in out/chess.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target rdm
# The face light (the diffuse light of every voxel face, docs/spec.md section 3.2) comes with
# it, at the scene's bake.face_light_spp (chess 64, island 8: docs/results.md section 1e).
scene="${1:-chess}"
./build/cli/rdm bake --scene "$scene" -o "out/$scene"
