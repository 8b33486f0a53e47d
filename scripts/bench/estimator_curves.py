#!/usr/bin/env python3
"""Error against time for the naive and the prefiltered estimator (docs/results.md).

Usage: estimator_curves.py BUILD_DIR OUT_DIR [--scenes chess,island] [--spp 4,16,64]
                           [--max-hemisphere N] [--figures DIR]

For every scene, estimator and spp: two bakes with seeds 1 and 2 (`rdm bake --backend cpu`),
the bake time of each (bake_report.json `seconds`, their mean) and the RMSE between the two
atlases after Reinhard c/(1+c) (`atlas_rmse`, no reference needed). Efficiency is
1 / (RMSE^2 t). Writes OUT_DIR/estimator_curves.json, prints a markdown table, and draws one
log-log SVG per scene into --figures (default OUT_DIR).
"""
import argparse
import json
import math
import os
import subprocess
import sys


def bake(build, scene, estimator, spp, seed, hemi, out):
    cmd = [os.path.join(build, "cli", "rdm"), "bake", "--scene", scene, "--backend", "cpu",
           "--estimator", estimator, "--spp", str(spp), "--seed", str(seed), "-q", "-o", out]
    if hemi:
        cmd += ["--max-hemisphere", str(hemi)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "bake_report.json")) as f:
        return json.load(f)["seconds"]


def rmse(build, a, b):
    out = subprocess.run([os.path.join(build, "eval", "atlas_rmse"), a, b], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["rmse_reinhard"]


def svg_plot(scene, rows, path):
    w, h, m = 560, 380, 60
    xs = [r["seconds"] for r in rows]
    ys = [r["rmse"] for r in rows]
    lx0, lx1 = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
    ly0, ly1 = math.floor(math.log10(min(ys))), math.ceil(math.log10(max(ys)))
    lx1, ly1 = max(lx1, lx0 + 1), max(ly1, ly0 + 1)

    def px(x):
        return m + (math.log10(x) - lx0) / (lx1 - lx0) * (w - 2 * m)

    def py(y):
        return h - m - (math.log10(y) - ly0) / (ly1 - ly0) * (h - 2 * m)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
             f'font-family="sans-serif" font-size="12">',
             f'<rect width="{w}" height="{h}" fill="white"/>',
             f'<text x="{w / 2}" y="20" text-anchor="middle" font-size="14">{scene}: seed-to-seed '
             f'RMSE (Reinhard) against bake time</text>']
    for e in range(lx0, lx1 + 1):
        x = px(10 ** e)
        parts.append(f'<line x1="{x}" y1="{m}" x2="{x}" y2="{h - m}" stroke="#ddd"/>')
        parts.append(f'<text x="{x}" y="{h - m + 16}" text-anchor="middle">{10 ** e:g} s</text>')
    for e in range(ly0, ly1 + 1):
        y = py(10 ** e)
        parts.append(f'<line x1="{m}" y1="{y}" x2="{w - m}" y2="{y}" stroke="#ddd"/>')
        parts.append(f'<text x="{m - 6}" y="{y + 4}" text-anchor="end">{10 ** e:g}</text>')
    colours = {"naive": "#c0392b", "prefiltered": "#2471a3"}
    for k, (est, colour) in enumerate(colours.items()):
        pts = sorted((r for r in rows if r["estimator"] == est), key=lambda r: r["seconds"])
        if not pts:
            continue
        line = " ".join(f'{px(r["seconds"]):.1f},{py(r["rmse"]):.1f}' for r in pts)
        parts.append(f'<polyline points="{line}" fill="none" stroke="{colour}" stroke-width="2"/>')
        for r in pts:
            parts.append(f'<circle cx="{px(r["seconds"]):.1f}" cy="{py(r["rmse"]):.1f}" r="3" '
                         f'fill="{colour}"/>')
            parts.append(f'<text x="{px(r["seconds"]) + 5:.1f}" y="{py(r["rmse"]) - 5:.1f}" '
                         f'fill="{colour}" font-size="10">{r["spp"]}</text>')
        parts.append(f'<text x="{w - m - 90}" y="{m + 16 * k + 10}" fill="{colour}">{est}</text>')
    parts.append(f'<text x="{w / 2}" y="{h - 15}" text-anchor="middle">bake wall time, 2 threads '
                 f'(labels: spp)</text>')
    parts.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("build")
    p.add_argument("out")
    p.add_argument("--scenes", default="chess,island")
    p.add_argument("--spp", default="4,16,64")
    p.add_argument("--max-hemisphere", type=int, default=0)
    p.add_argument("--figures", default="")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for scene in a.scenes.split(","):
        for spp in [int(s) for s in a.spp.split(",")]:
            for est in ("naive", "prefiltered"):  # side by side at each spp
                dirs = [os.path.join(a.out, f"{scene}_{est}_{spp}_s{seed}") for seed in (1, 2)]
                t = [bake(a.build, scene, est, spp, seed, a.max_hemisphere, d)
                     for seed, d in zip((1, 2), dirs)]
                e = rmse(a.build, dirs[0], dirs[1])
                sec = sum(t) / 2
                rows.append({"scene": scene, "estimator": est, "spp": spp, "seconds": sec,
                             "rmse": e, "efficiency": 1.0 / (e * e * sec)})
                print(f"{scene} {est} spp {spp}: {sec:.2f} s, RMSE {e:.5f}", file=sys.stderr)
    with open(os.path.join(a.out, "estimator_curves.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print("| scene | estimator | spp | time (s) | RMSE | efficiency 1/(RMSE² t) |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f'| {r["scene"]} | {r["estimator"]} | {r["spp"]} | {r["seconds"]:.2f} | '
              f'{r["rmse"]:.5f} | {r["efficiency"]:.0f} |')
    fig = a.figures or a.out
    os.makedirs(fig, exist_ok=True)
    for scene in a.scenes.split(","):
        svg_plot(scene, [r for r in rows if r["scene"] == scene],
                 os.path.join(fig, f"estimator_{scene}.svg"))


if __name__ == "__main__":
    main()
