#!/usr/bin/env bash
# Fresh Debian 12 machine -> the RDM atlas of the built-in default scene (chess) in out/chess.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target rdm
# --face-light: the diffuse light of every voxel face as well (docs/spec.md section 3.2), at 8
# samples per face on island, whose 104,390 exposed faces at 64 would cost 3x its RDMs
# (docs/results.md section 1d).
scene="${1:-chess}"
face_light_spp=64
[[ "$scene" == island ]] && face_light_spp=8
./build/cli/rdm bake --scene "$scene" -o "out/$scene" --face-light "$face_light_spp"
