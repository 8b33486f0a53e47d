#!/usr/bin/env python3
"""A generated city-like world of about N RDMs for the memory benchmarks (docs/performance.md).

Blocks stand on every other slot of a square grid (a pillar shape, so no face is skipped),
alternating a diffuse and a glossy palette colour: a diffuse block has one RDM (level 7), a
glossy one two (levels 7 and 3). Writes an rdm-scene to stdout.

  python3 bench/gen_world.py --rdms 20000 > world.json
"""
import argparse
import base64
import json
import math


def pillar(index):
    voxels = bytearray(4096)
    for z in range(16):
        for y in range(12):
            for x in range(16):
                if 3 <= x < 13 and 3 <= z < 13 or y < 2:
                    voxels[x + 16 * (y + 16 * z)] = index
    return base64.b64encode(bytes(voxels)).decode()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rdms", type=int, default=20000, help="about this many RDMs")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--max-hemisphere", type=int, default=16)
    a = ap.parse_args()
    blocks = math.ceil(a.rdms / 1.5)  # half diffuse (1 RDM), half glossy (2 RDMs)
    layers = max(1, math.ceil(blocks / (128 * 128)))
    side = min(256, max(2, math.ceil(math.sqrt(2 * blocks / layers))))
    placements = []
    for j in range(layers):
        for k in range(side):
            for i in range(side):
                if (i + k) % 2 or len(placements) >= blocks:
                    continue
                name = "matte" if (i // 2 + k) % 2 else "gloss"
                placements.append({"at": [i, 2 * j, k], "block": name, "rot": 0})
    scene = {
        "format": "rdm-scene", "version": 1,
        "size": [side, 2 * layers, side],
        "palette": [{"color": [190, 180, 170], "roughness": 7, "metallic": 0, "emission": 0},
                    {"color": [120, 140, 170], "roughness": 3, "metallic": 1, "emission": 0}],
        "blocks": {"matte": {"voxels": pillar(1)}, "gloss": {"voxels": pillar(2)}},
        "placements": placements,
        "sun": {"direction": [0.4, 1.0, 0.3], "irradiance": [3.0, 2.9, 2.7],
                "angular_radius_deg": 0.27},
        "sky": {"zenith": [0.3, 0.5, 0.9], "horizon": [0.8, 0.85, 0.9],
                "ground": [0.2, 0.18, 0.15]},
        "ambient": [0.2, 0.2, 0.25],
        "bake": {"spp": a.spp, "max_bounces": 2, "seed": 1, "max_hemisphere": a.max_hemisphere},
        "cameras": [{"position": [-4.0, 20.0, -4.0], "target": [side * 8.0, 0.0, side * 8.0],
                     "fov_deg": 50}],
    }
    json.dump(scene, __import__("sys").stdout)


if __name__ == "__main__":
    main()
