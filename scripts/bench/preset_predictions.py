#!/usr/bin/env python3
"""Predicted against measured bake time and noise of the quality presets (docs/results.md).

Usage: preset_predictions.py BUILD_DIR OUT_DIR [--scenes chess,island,terrain,furnace]
                             [--repeats 2]

Runs `rdm bake --scene S --quality Q --backend cpu` for every built-in scene and preset and
reads bake_report.json: `predicted.seconds` (from the pilot, before the bake) beside `seconds`
(the bake), `predicted.cpu_seconds` beside `cpu_seconds`, and the predicted beside the measured mean relative standard error. Prints a
markdown table and writes OUT_DIR/preset_predictions.json.
"""
import argparse
import json
import os
import subprocess


def main():
    p = argparse.ArgumentParser()
    p.add_argument("build")
    p.add_argument("out")
    p.add_argument("--scenes", default="chess,island,terrain,furnace")
    p.add_argument("--repeats", type=int, default=2)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for scene in a.scenes.split(","):
        for quality in ("draft", "preview", "final"):
            for r in range(a.repeats):
                out = os.path.join(a.out, f"{scene}_{quality}_{r}")
                subprocess.run([os.path.join(a.build, "cli", "rdm"), "bake", "--scene", scene,
                                "--quality", quality, "--backend", "cpu", "-q", "-o", out],
                               check=True, stdout=subprocess.DEVNULL)
                with open(os.path.join(out, "bake_report.json")) as f:
                    j = json.load(f)
                rows.append({"scene": scene, "quality": quality, "run": r, "spp": j["spp"],
                             "predicted_s": j["predicted"]["seconds"], "measured_s": j["seconds"],
                             "predicted_cpu_s": j["predicted"]["cpu_seconds"],
                             "measured_cpu_s": j["cpu_seconds"],
                             "pilot_s": j["predicted"]["pilot_seconds"],
                             "predicted_error": j["predicted"]["mean_relative_error"],
                             "measured_error": j["mean_relative_error"]})
    with open(os.path.join(a.out, "preset_predictions.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print("| scene | quality | spp | predicted s | measured s | ratio | predicted CPU-s | "
          "measured CPU-s | ratio | pilot s | predicted noise | measured noise |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")

    def ratio(p, m):
        return p / m if m > 0 else float("nan")

    for r in rows:
        print(f'| {r["scene"]} | {r["quality"]} | {r["spp"]} | {r["predicted_s"]:.3f} | '
              f'{r["measured_s"]:.3f} | {ratio(r["predicted_s"], r["measured_s"]):.2f} | '
              f'{r["predicted_cpu_s"]:.3f} | {r["measured_cpu_s"]:.3f} | '
              f'{ratio(r["predicted_cpu_s"], r["measured_cpu_s"]):.2f} | {r["pilot_s"]:.2f} | '
              f'{100 * r["predicted_error"]:.2f} % | {100 * r["measured_error"]:.2f} % |')


if __name__ == "__main__":
    main()
